//! Indexing by a run-time value (`a[i]`) → Rust, for the inside of a
//! controller module: reads through `rt::index::element`, assignments
//! through `rt::index::element_mut`, never `[]`, so no cycle can panic. An
//! index out of range marks the cycle on the controller's bookkeeping; the
//! code here then skips the rest of the cycle's jobs and a row firing ends
//! the plan with `INDEX_RANGE` (the reference interpreter, `rcs_dsl::interp`,
//! does the same step for step). Code without a run-time index is generated
//! exactly as before.

use super::expr::{zero, Code, Gen};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use rcs_dsl::ast::AssignOp;
use rcs_dsl::ir::*;

impl Gen<'_> {
    /// `base[i]` for a run-time `i`: the element, or its type's zero.
    pub(super) fn index_by(&self, base: &Expr, i: &Expr, elem: &Type) -> Code {
        let b = self.expr(base);
        let ix = self.expr(i);
        let (bt, it) = (b.at(Code::ATOM), &ix.ts);
        let z = zero(self.names, elem);
        Code::new(
            quote!(rt::index::element(&#bt, #it, #z, &mut self.bk)),
            Code::ATOM,
            b.has_block || ix.has_block,
        )
    }

    /// The jobs in order; after a job that can index out of range, the
    /// rest is skipped if it did.
    pub(super) fn jobs(&self, jobs: &[Job]) -> TokenStream {
        let Some(last) = jobs.iter().rposition(Job::indexes_by_value) else {
            let code = jobs.iter().map(|j| self.job(j));
            return quote!(#(#code)*);
        };
        if last + 1 == jobs.len() && !jobs[..last].iter().any(Job::indexes_by_value) {
            // Only the last job can meet it: nothing to skip.
            let code = jobs.iter().map(|j| self.job(j));
            return quote!(#(#code)*);
        }
        let code = jobs.iter().enumerate().map(|(n, j)| {
            let c = self.job(j);
            if j.indexes_by_value() && n + 1 < jobs.len() {
                quote!(#c if self.bk.index_range_hit() { break 'jobs; })
            } else {
                c
            }
        });
        quote!('jobs: { #(#code)* })
    }

    /// A job that can index out of range: its values first (the value,
    /// then the place's indices, or a send's arguments), then the job only
    /// if no index was out of range.
    pub(super) fn checked_job(&self, j: &Job) -> Option<TokenStream> {
        if !j.indexes_by_value() {
            return None;
        }
        match j {
            Job::Assign {
                place, op, value, ..
            } => Some(self.checked_assign(place, *op, value)),
            Job::Send {
                sub, command, args, ..
            } => {
                let locals: Vec<_> = (0..args.len()).map(|n| format_ident!("arg{n}")).collect();
                let vals: Vec<TokenStream> = args.iter().map(|a| self.expr(a).ts).collect();
                let uses: Vec<TokenStream> = locals.iter().map(|l| quote!(#l)).collect();
                let send = self.send(*sub, *command, &uses);
                Some(quote!({
                    #(let #locals = #vals;)*
                    if !self.bk.index_range_hit() { #send }
                }))
            }
            _ => None,
        }
    }

    fn checked_assign(&self, place: &Place, op: AssignOp, value: &Expr) -> TokenStream {
        let v = self.expr(value).ts;
        let locals: Vec<_> = (0..place.indices.len())
            .map(|n| format_ident!("at{n}"))
            .collect();
        let indices: Vec<TokenStream> = place.indices.iter().map(|i| self.expr(i).ts).collect();
        // The place, one `element_mut` per run-time index, innermost last.
        let (root, mut ty) = self.place_root(place);
        let mut path = root;
        let mut opened = Vec::new();
        // Right after an `element_mut`, the path is the slot it opened:
        // `(*slot)` as a whole, plain `slot` before a field (auto-deref,
        // which clippy wants spelt so).
        let mut slot_opened: Option<proc_macro2::Ident> = None;
        for proj in &place.path {
            let base = match slot_opened.take() {
                Some(slot) if matches!(proj, Projection::Field(_)) => quote!(#slot),
                _ => path.clone(),
            };
            match (proj, &ty) {
                (Projection::Field(f), Type::Buffer(bt)) => {
                    let field = &self.names.buffers[bt.index()].fields[*f as usize];
                    path = quote!(#base.#field);
                    ty = self.ir.buffer_types[bt.index()].fields[*f as usize]
                        .ty
                        .clone();
                }
                (Projection::Index(i), Type::Array(elem, _)) => {
                    let i = proc_macro2::Literal::usize_unsuffixed(*i as usize);
                    path = quote!(#path[#i]);
                    ty = (**elem).clone();
                }
                (Projection::IndexBy(k), Type::Array(elem, _)) => {
                    let slot = format_ident!("slot{}", opened.len());
                    let at = &locals[*k as usize];
                    opened.push(quote!(rt::index::element_mut(&mut #path, #at, &mut self.bk)));
                    path = quote!((*#slot));
                    slot_opened = Some(slot);
                    ty = (**elem).clone();
                }
                _ => unreachable!("projections follow the place's type"),
            }
        }
        let assign = match (op, &place.ty) {
            (AssignOp::Set, _) => quote!(#path = value;),
            (AssignOp::Add, Type::Int(_)) => quote!(#path = #path.wrapping_add(value);),
            (AssignOp::Sub, Type::Int(_)) => quote!(#path = #path.wrapping_sub(value);),
            (AssignOp::Add, _) => quote!(#path += value;),
            (AssignOp::Sub, _) => quote!(#path -= value;),
        };
        let mut body = assign;
        for (n, open) in opened.iter().enumerate().rev() {
            let slot = format_ident!("slot{n}");
            body = quote!(if let Some(#slot) = #open { #body });
        }
        quote!({
            let value = #v;
            #(let #locals = #indices;)*
            if !self.bk.index_range_hit() { #body }
        })
    }
}

/// A row's condition that can index out of range: it holds only if no
/// index was (the rows after it are guarded with [`after_index`]).
pub(super) fn guarded_condition(c: Code) -> Code {
    let ts = c.at(Code::AND);
    Code::new(
        quote!(#ts && !self.bk.index_range_hit()),
        Code::AND,
        c.has_block,
    )
}

/// Steps 4 and 4b of a controller's `cycle`: deciding and the `post`
/// jobs. In a controller that indexes by a value, an index out of range in
/// `pre` skips both, one in the rows skips `post`, and the cycle ends the
/// plan with `INDEX_RANGE` after them.
pub(super) fn cycle_steps(c: &Controller, post: TokenStream) -> (TokenStream, TokenStream) {
    if !indexes_by_value(c) {
        return (
            quote!(if self.bk.is_active() {
                self.decide(subs);
            }),
            post,
        );
    }
    let post = if post.is_empty() {
        post
    } else {
        quote!(if !self.bk.index_range_hit() { #post })
    };
    (
        quote!(if self.bk.is_active() && !self.bk.index_range_hit() {
            self.decide(subs);
        }),
        quote!(#post self.bk.end_index_range();),
    )
}

/// Whether anything the controller evaluates can index by a run-time
/// value: an expression, or the place a job assigns (`t.rows[i].x = …`
/// holds no index expression, yet can meet an index out of range).
fn indexes_by_value(c: &Controller) -> bool {
    let rows = || c.plans.iter().flat_map(|p| &p.rows);
    let blocks = c.pre.iter().chain(c.post.iter()).map(|b| &b.jobs);
    let in_jobs = blocks
        .chain(rows().map(|r| &r.jobs))
        .flatten()
        .any(Job::indexes_by_value);
    in_jobs || rows().any(|r| matches!(&r.cond, Condition::When(e) if e.indexes_by_value()))
}

/// The condition of a row after one that can index out of range: tried
/// only if no index was.
pub(super) fn after_index(c: Code) -> Code {
    let ts = c.at(Code::AND);
    Code::new(
        quote!(!self.bk.index_range_hit() && #ts),
        Code::AND,
        c.has_block,
    )
}
