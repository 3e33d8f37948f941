//! The unknowns of the discrete momentum rows ([`super::momentum_rows`]) as named column
//! blocks: the layout of `x` is this list, and every column index follows from it.
//!
//! ```text
//! x = [ X₀ (3) │ X₁ (3) │ m (3) │ c (3) │ τ_b (3) │ κ (1) │ D (1) │ j (6) ]
//!       ╰── per chain ──╯ ╰─────────────── shared by every chain ──────────────╯
//! ```
//!
//! * **Per chain** ([`Scope::Chain`]): unknowns of one chain of rows, minimised out as the
//!   chain's rows arrive ([`super::augmented_qr`]); they come first.
//! * **Shared** ([`Scope::Shared`]): unknowns every chain has, held in one fixed-size
//!   factor ([`super::shared_qr`]); `j` comes last, so that the trailing 6×6 block of the
//!   factor is the reduced problem in `j` alone.
//!
//! A block a row model does not use keeps its columns at zero (the factor skips a zero
//! pivot), and is not counted as an unknown ([`super::momentum_rows::MomentumRowSettings::shared_nuisance`];
//! the outside torques' blocks `m` and `c` count from the first row that uses them,
//! [`super::external_torque`]).
//!
//! Adding a physical unknown is one entry in [`Block::ALL`] with its width, scope and
//! name; the rows that fill its columns ([`super::momentum_rows`]); the setting that
//! switches it ([`super::momentum_rows::MomentumRowSettings`]); and its report line. The
//! fixed-size factor's unrolled fold checks its pivot count against [`SHARED`] at compile
//! time.

/// Where a block's unknowns live.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scope {
    /// One set per chain of rows, minimised out per chain.
    Chain,
    /// One set for the whole record.
    Shared,
}

/// A block of columns of the unknown vector `x`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Block {
    /// `X₀`: the chain's initial momentum, N m s (plain rows; even Richardson centres).
    Anchor0,
    /// `X₁`: the initial momentum of the odd Richardson centres' subgrid, N m s.
    Anchor1,
    /// `τ_b`: a constant disturbance torque fixed in the body frame, N m.
    BodyTorque,
    /// `κ`: the wheel-momentum curvature coefficient of the adaptive stencil.
    Kappa,
    /// `m`: a residual magnetic dipole fixed in the body, A m² ([`super::external_torque`]).
    Dipole,
    /// `c`: the centre of mass from the known torque's origin, body axes, m
    /// ([`super::external_torque`]).
    CentreOfMass,
    /// `D`: the coefficient of a linear damping torque `−D ω` (air drag), N m s.
    Damping,
    /// `j = [J11, J22, J33, J12, J13, J23]`, kg m².
    J,
}

impl Block {
    /// Every block, in column order: per-chain blocks first, `j` last.
    pub(crate) const ALL: [Block; 8] = [
        Block::Anchor0,
        Block::Anchor1,
        Block::Dipole,
        Block::CentreOfMass,
        Block::BodyTorque,
        Block::Kappa,
        Block::Damping,
        Block::J,
    ];

    /// Columns of the block.
    #[must_use]
    pub(crate) const fn width(self) -> usize {
        match self {
            Block::Anchor0
            | Block::Anchor1
            | Block::BodyTorque
            | Block::Dipole
            | Block::CentreOfMass => 3,
            Block::Kappa | Block::Damping => 1,
            Block::J => 6,
        }
    }

    /// Where its unknowns live.
    #[must_use]
    pub(crate) const fn scope(self) -> Scope {
        match self {
            Block::Anchor0 | Block::Anchor1 => Scope::Chain,
            Block::BodyTorque
            | Block::Kappa
            | Block::Dipole
            | Block::CentreOfMass
            | Block::Damping
            | Block::J => Scope::Shared,
        }
    }

    /// Name for reports.
    #[cfg(test)]
    #[must_use]
    pub(crate) const fn name(self) -> &'static str {
        match self {
            Block::Anchor0 => "initial momentum",
            Block::Anchor1 => "initial momentum (odd subgrid)",
            Block::BodyTorque => "body-frame torque",
            Block::Kappa => "wheel-momentum curvature",
            Block::Dipole => "residual magnetic dipole",
            Block::CentreOfMass => "centre of mass",
            Block::Damping => "damping",
            Block::J => "inertia",
        }
    }

    /// Its first column in `x`.
    #[must_use]
    pub(crate) const fn column(self) -> usize {
        let mut column = 0;
        let mut i = 0;
        while i < Self::ALL.len() {
            if Self::ALL[i] as u8 == self as u8 {
                return column;
            }
            column += Self::ALL[i].width();
            i += 1;
        }
        panic!("every block is in Block::ALL")
    }

    /// Its first column among the shared unknowns (a shared block).
    #[must_use]
    pub(crate) const fn shared_column(self) -> usize {
        self.column() - FIRST_SHARED
    }
}

const fn total(scope: Option<Scope>) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < Block::ALL.len() {
        let b = Block::ALL[i];
        if match scope {
            None => true,
            Some(s) => b.scope() as u8 == s as u8,
        } {
            n += b.width();
        }
        i += 1;
    }
    n
}

/// Number of unknowns in one row block.
pub(crate) const UNKNOWNS: usize = total(None);
/// Number of per-chain unknowns (the first columns).
pub(crate) const PER_CHAIN: usize = total(Some(Scope::Chain));
/// Number of shared unknowns (the columns from [`FIRST_SHARED`] on).
pub(crate) const SHARED: usize = total(Some(Scope::Shared));
/// The first shared column.
pub(crate) const FIRST_SHARED: usize = PER_CHAIN;

const _: () = {
    // Per-chain blocks first, then shared ones, `j` last: the factors rely on it.
    let mut i = 0;
    let mut shared = false;
    while i < Block::ALL.len() {
        let s = matches!(Block::ALL[i].scope(), Scope::Shared);
        assert!(shared <= s, "per-chain blocks come before shared ones");
        shared = s;
        i += 1;
    }
    assert!(
        Block::J.column() + Block::J.width() == UNKNOWNS,
        "j comes last"
    );
    assert!(PER_CHAIN + SHARED == UNKNOWNS);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_unknowns_in_order() {
        let mut next = 0;
        for b in Block::ALL {
            assert_eq!(b.column(), next, "{}", b.name());
            next += b.width();
        }
        assert_eq!(next, UNKNOWNS);
        assert_eq!(Block::J.shared_column() + 6, SHARED);
        assert_eq!(Block::Dipole.column(), FIRST_SHARED);
    }
}
