//! Wheel torque commands held constant (zero-order hold) at a controller rate.
//!
//! A flight controller computes the wheel torque command `ρ̇` (N m, body axes) at
//! discrete ticks and holds it until the next one. The ticks are at
//!
//! ```text
//! t_j = t0_s + phase_s + j / rate_hz,   j = 0, 1, 2, …
//! ```
//!
//! so `phase_s = 0` puts a tick on every telemetry node (when the telemetry period is a
//! multiple of the controller period) and `phase_s = h/2` makes the commands change
//! half-way between telemetry samples. At a tick the control law
//! ([`super::InputLaw`]) is evaluated once, on the **true** state at that instant, and
//! its value is held. Before the first tick (`phase_s > 0`) the command evaluated at
//! `t0_s` is held.
//!
//! The simulator splits every integration interval at the ticks inside it, so no RK4
//! substep straddles a change of command: ρ is then exactly piecewise linear and the
//! integration keeps its fourth order (`tests/integration/sim_realism.rs`).

use super::SimError;

/// The most command ticks allowed in one integration node period.
pub(crate) const MAX_TICKS_PER_NODE: f64 = 1000.0;

/// Zero-order hold of the wheel torque commands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandHold {
    /// Controller (command update) rate, Hz; finite and > 0.
    pub rate_hz: f64,
    /// Time of the first tick after `t0_s`, s; `0 ≤ phase_s < 1/rate_hz`.
    pub phase_s: f64,
}

impl CommandHold {
    /// Commands at `rate_hz` with ticks on the telemetry nodes (phase 0).
    #[must_use]
    pub fn at(rate_hz: f64) -> Self {
        Self {
            rate_hz,
            phase_s: 0.0,
        }
    }

    /// Controller period `1/rate_hz`, s.
    #[must_use]
    pub(crate) fn period_s(&self) -> f64 {
        1.0 / self.rate_hz
    }

    /// Time of tick `j`, s, for a run starting at `t0_s`.
    #[must_use]
    pub(crate) fn tick_s(&self, t0_s: f64, j: u64) -> f64 {
        t0_s + self.phase_s + j as f64 * self.period_s()
    }

    /// Check the rate and the phase; `dt_s` is the integration node period, which may
    /// hold at most [`MAX_TICKS_PER_NODE`] ticks.
    pub(crate) fn validate(&self, dt_s: f64) -> Result<(), SimError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return Err(SimError::InvalidSetting {
                field: "commands.rate_hz",
                value: self.rate_hz,
                why: "must be finite and > 0",
            });
        }
        if self.rate_hz * dt_s > MAX_TICKS_PER_NODE {
            return Err(SimError::InvalidSetting {
                field: "commands.rate_hz",
                value: self.rate_hz,
                why: "must not exceed 1000 ticks per integration node period dt_s",
            });
        }
        if !(self.phase_s.is_finite() && self.phase_s >= 0.0 && self.phase_s < self.period_s()) {
            return Err(SimError::InvalidSetting {
                field: "commands.phase_s",
                value: self.phase_s,
                why: "must be finite, >= 0 and < the controller period 1/rate_hz",
            });
        }
        Ok(())
    }
}

/// The tick schedule during a run: the index and time of the next tick.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ticker {
    hold: CommandHold,
    t0_s: f64,
    next: u64,
    /// Time of tick `next`, s.
    pub(crate) next_s: f64,
}

impl Ticker {
    /// The schedule after `t0_s`: ticks within `eps_s` of `t0_s` count as taken (the
    /// command at `t0_s` is evaluated at the start in any case).
    pub(crate) fn new(hold: CommandHold, t0_s: f64, eps_s: f64) -> Self {
        let mut t = Self {
            hold,
            t0_s,
            next: 0,
            next_s: hold.tick_s(t0_s, 0),
        };
        while t.next_s <= t0_s + eps_s {
            t.advance();
        }
        t
    }

    /// Move to the following tick.
    pub(crate) fn advance(&mut self) {
        self.next += 1;
        self.next_s = self.hold.tick_s(self.t0_s, self.next);
    }
}
