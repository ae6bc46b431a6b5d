//! Generated Rust for watchdogs on `reads` buffers (LANGUAGE.md §8,
//! SEMANTICS.md step 6): for each buffer a controller watches
//! (`B.stale_cycles`, `B.stale_time`), a `rt::BufferWatch` field fed with
//! the generation of each cycle's read. A buffer nobody watches is read
//! exactly as before, so a controller without watchdogs generates the same
//! code as before they existed.

use crate::ident::prefixed;
use proc_macro2::{Ident, TokenStream};
use quote::quote;
use rcs_dsl::ir::Controller;

/// The watch fields of a controller and its step-1 read statements.
pub(super) struct Watches {
    /// `watch_B` for each watched buffer.
    pub fields: Vec<Ident>,
    /// One statement per `reads` buffer, in order: the copy into
    /// `data.reads`, and for a watched one the watch's update from the
    /// same read (one read: the value and generation belong together).
    pub reads: Vec<TokenStream>,
}

impl Watches {
    pub fn new(c: &Controller, read_fields: &[Ident], read_handles: &[Ident]) -> Watches {
        let watched = rcs_dsl::watchdog::watched_reads(c);
        let mut fields = Vec::new();
        let reads = read_fields
            .iter()
            .zip(read_handles)
            .zip(watched)
            .map(|((f, h), watched)| {
                if watched {
                    let w = prefixed("watch", f);
                    fields.push(w.clone());
                    quote! {
                        let read = self.#h.read();
                        self.#w.observe(read.generation);
                        self.data.reads.#f = read.value;
                    }
                } else {
                    quote!(self.data.reads.#f = self.#h.read().value;)
                }
            })
            .collect();
        Watches { fields, reads }
    }
}
