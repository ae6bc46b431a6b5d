//! Every plan set of the repository, compiled by rcsc through build.rs
//! (`plans/*` as `set_submarine`, `set_figure13`; the golden ok cases as
//! `set_0001_minimal`, …), plus two reference implementations of
//! propulsion's AHEAD plan for the benchmark in `benches/pr_cycle.rs`.

include!(concat!(env!("OUT_DIR"), "/sets.rs"));

pub mod c_port;
pub mod hand;
pub mod servo;
