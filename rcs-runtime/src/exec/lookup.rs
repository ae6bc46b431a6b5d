//! Looking an executive's controllers up by name — their names, timing,
//! panics and the controllers themselves, as `dyn Controller` or as their
//! own types. Setup, tests and displays use these; the cycle path never
//! does.

use std::any::Any;

use super::{Controller, ControllerStats, Executive};
use crate::plan::Bookkeeping;

impl Executive {
    /// Names of the controllers in execution order.
    pub fn controller_names(&self) -> impl Iterator<Item = &str> {
        self.slots.iter().map(|s| s.name.as_str())
    }
    /// Execution-time statistics of controller `name`.
    pub fn controller_stats(&self, name: &str) -> Option<&ControllerStats> {
        self.slots.iter().find(|s| s.name == name).map(|s| &s.stats)
    }
    /// The message of the last panic caught in controller `name`'s cycle
    /// (`None`: it never panicked, or there is no such controller).
    pub fn last_panic(&self, name: &str) -> Option<&str> {
        self.slots
            .iter()
            .find(|s| s.name == name)
            .and_then(|s| s.last_panic.as_deref())
    }
    /// Commands overwritten in controller `name`'s command buffer before it
    /// read them ([`Bookkeeping::commands_lost`]; 0 for a controller
    /// without bookkeeping, or one not on this executive).
    pub fn commands_lost(&self, name: &str) -> u64 {
        self.controller(name)
            .and_then(|c| c.bookkeeping())
            .map_or(0, Bookkeeping::commands_lost)
    }
    /// Per subordinate of controller `name`, the cycles in which it echoed
    /// an older serial than the last command sent (empty for a controller
    /// without subordinates, or one not on this executive).
    pub fn old_echoes(&self, name: &str) -> Vec<(String, u64)> {
        let mut out = Vec::new();
        if let Some(c) = self.controller(name) {
            c.old_echoes(&mut |sub, n| out.push((sub.to_string(), n)));
        }
        out
    }
    /// Controller `name` itself (e.g. to inspect its bookkeeping).
    pub fn controller(&self, name: &str) -> Option<&dyn Controller> {
        self.slots
            .iter()
            .find(|s| s.name == name)
            .map(|s| s.ctrl.as_ref())
    }
    /// The controller called `name` as its own type `T`: `None` if there is
    /// none or it is not a `T`. A lookup by name, not for the cycle path.
    pub fn controller_as<T: Controller>(&self, name: &str) -> Option<&T> {
        let any: &dyn Any = self.controller(name)?;
        any.downcast_ref()
    }
    /// [`controller_as`](Self::controller_as), mutably (between cycles: to
    /// adjust a controller's hand-written hooks, say).
    pub fn controller_as_mut<T: Controller>(&mut self, name: &str) -> Option<&mut T> {
        let any: &mut dyn Any = self.controller_mut(name)?;
        any.downcast_mut()
    }
    /// Controller `name` itself, mutably.
    pub fn controller_mut(&mut self, name: &str) -> Option<&mut dyn Controller> {
        let slot = self.slots.iter_mut().find(|s| s.name == name)?;
        Some(slot.ctrl.as_mut())
    }
    /// Controller `name` on whichever of `executives` runs it, as its own
    /// type `T`: what generated `System` accessors call. The search is not
    /// generic; only the final downcast is.
    pub fn find_as<'a, T: Controller>(executives: &'a [Executive], name: &str) -> Option<&'a T> {
        let any: &dyn Any = Self::find(executives, name)?;
        any.downcast_ref()
    }
    /// [`find_as`](Self::find_as), mutably.
    pub fn find_as_mut<'a, T: Controller>(
        executives: &'a mut [Executive],
        name: &str,
    ) -> Option<&'a mut T> {
        let any: &mut dyn Any = Self::find_mut(executives, name)?;
        any.downcast_mut()
    }
    fn find<'a>(executives: &'a [Executive], name: &str) -> Option<&'a dyn Controller> {
        executives.iter().find_map(|e| e.controller(name))
    }
    fn find_mut<'a>(executives: &'a mut [Executive], name: &str) -> Option<&'a mut dyn Controller> {
        executives.iter_mut().find_map(|e| e.controller_mut(name))
    }
}
