//! Safe wrappers over the C port of the methodology's controller template
//! (`c/pr_template.c`, compiled with `-O2` by build.rs). The C code keeps
//! its state in statics, as the template does, so the wrappers take a
//! `&mut CPropulsion` token of which only one exists at a time.

use std::sync::atomic::{AtomicBool, Ordering};

extern "C" {
    fn pr_c_reset();
    fn pr_c_command_ahead(speed: f64);
    fn pr_c_world(ship_speed: f64);
    fn pr_c_controller();
    fn pr_c_state() -> u32;
    fn pr_c_status() -> u32;
    fn pr_c_rpm() -> f64;
    fn pr_c_ordered_rpm() -> f64;
    fn pr_c_ship_speed() -> f64;
}

static TAKEN: AtomicBool = AtomicBool::new(false);

/// The one handle on the C controller's statics.
#[derive(Debug)]
pub struct CPropulsion(());

impl CPropulsion {
    /// The handle, reset; `None` while another one is alive.
    pub fn take() -> Option<CPropulsion> {
        if TAKEN.swap(true, Ordering::AcqRel) {
            return None;
        }
        // SAFETY: only the holder of the single token touches the C statics.
        unsafe { pr_c_reset() };
        Some(CPropulsion(()))
    }

    pub fn command_ahead(&mut self, speed: f64) {
        // SAFETY: see `take`.
        unsafe { pr_c_command_ahead(speed) }
    }

    /// Play the turbine (DONE to its last command) and the ship.
    pub fn world(&mut self, ship_speed: f64) {
        // SAFETY: see `take`.
        unsafe { pr_c_world(ship_speed) }
    }

    /// One control cycle.
    pub fn cycle(&mut self) {
        // SAFETY: see `take`.
        unsafe { pr_c_controller() }
    }

    pub fn state(&self) -> u32 {
        // SAFETY: see `take`.
        unsafe { pr_c_state() }
    }

    pub fn status(&self) -> u32 {
        // SAFETY: see `take`.
        unsafe { pr_c_status() }
    }

    pub fn rpm(&self) -> f64 {
        // SAFETY: see `take`.
        unsafe { pr_c_rpm() }
    }

    /// PR's status fields: the RPM last ordered and the ship speed read.
    pub fn status_fields(&self) -> (f64, f64) {
        // SAFETY: see `take`.
        unsafe { (pr_c_ordered_rpm(), pr_c_ship_speed()) }
    }
}

impl Drop for CPropulsion {
    fn drop(&mut self) {
        TAKEN.store(false, Ordering::Release);
    }
}
