//! Every plan set of the repository, compiled by rcsc through build.rs
//! (`plans/*` as `set_submarine`, `set_figure13`; the golden ok cases as
//! `set_0001_minimal`, …), plus two reference implementations of
//! propulsion's AHEAD plan for the benchmark in `benches/pr_cycle.rs`.

include!(concat!(env!("OUT_DIR"), "/sets.rs"));

/// One plan set of the repository, compiled with its scenario driver.
pub struct PlanSet {
    /// The folder or `.rcs` file, relative to the workspace root.
    pub path: &'static str,
    /// A fresh generated controller of the set, by name, behind
    /// `rcs_runtime::driver::Driven` (`None`: no such controller).
    pub new_driver: rcs_runtime::driver::Factory,
    /// A fresh generated run of the named controllers of the set (whole
    /// subtrees) behind `rcs_runtime::driver::DrivenSystem`.
    pub new_system_driver: rcs_runtime::driver::SystemFactory,
}

pub mod c_port;
pub mod hand;
pub mod servo;
