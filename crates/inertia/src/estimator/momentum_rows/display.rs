//! The row settings in words, for reports.

use super::{MomentumRowSettings, RotationSource, Stencil};

/// One line for reports, e.g. `rotation from gyro, Richardson rows (ρ held over each
/// step), unknown constant torque`.
impl core::fmt::Display for MomentumRowSettings {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let rotation = match self.rotation {
            RotationSource::Attitude => "rotation from attitude",
            RotationSource::Gyro => "rotation from gyro",
        };
        let stencil = match self.stencil {
            Stencil::Plain => "plain rows",
            Stencil::Smooth => "Richardson rows (smooth ρ)",
            Stencil::Held => "Richardson rows (ρ held over each step)",
            Stencil::Adaptive => "Richardson rows (ρ curvature estimated)",
        };
        let torque = if self.torque_bias {
            ", unknown constant torque"
        } else {
            ""
        };
        let inertial = if self.inertial_torque {
            ", unknown inertial torque per chain"
        } else {
            ""
        };
        let damping = if self.damping {
            ", unknown damping"
        } else {
            ""
        };
        write!(f, "{rotation}, {stencil}{torque}{inertial}{damping}")?;
        if let Some(max) = self.max_chain_s {
            write!(f, ", chains of {max} s")?;
        }
        Ok(())
    }
}
