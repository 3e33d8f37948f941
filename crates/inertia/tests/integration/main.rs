//! The library's integration tests, one binary (one link, one set of monomorphised
//! dependencies): each module is one subject. `no_alloc` stays a binary of its own, as it
//! counts allocations process-wide.

mod common;
mod trajectory;

mod attitude;
mod attitude_drift;
mod attitude_from_gyro;
mod changing_inertia;
mod consistency;
mod constraints;
mod csv_robustness;
mod damping;
mod discrete_convergence;
mod discrete_momentum;
mod dynamics;
mod estimators;
mod gyro_range;
mod inertial_torque;
mod lab_realism;
mod numeric_range;
mod outside_torques;
mod pipeline;
mod prior;
mod records;
mod rotor_calibration;
mod rotor_inertia;
mod rotor_scale;
mod rotor_time_tags;
mod short_records;
mod sim_effects;
mod sim_realism;
mod solver_random;
mod uncertainty;
mod wheel_delay;
