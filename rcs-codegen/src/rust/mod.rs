//! IR → one Rust module for the whole plan set: `quote` builds the tokens,
//! `syn` checks they form a file, `prettyplease` prints them, and the row
//! comments (which tokens cannot carry) are put back in at their markers.
//! The writers then pass the text through rustfmt when it is installed
//! ([`crate::rustfmt`]); this module stays a pure function of the IR.

mod accept;
mod builtins;
mod codes;
mod controller;
mod driver;
mod every_cycle;
mod expr;
mod index;
mod instances;
mod names;
mod plan;
mod process;
mod schema;
mod shape;
mod system;
mod system_driver;
mod types;
mod verbs;
mod watchdog;

use crate::GENERATED;
use proc_macro2::TokenStream;
use quote::quote;
use rcs_dsl::ir::Ir;

/// Comments to put back after printing, found by their marker statements.
pub(crate) struct Comments {
    texts: Vec<String>,
}

const MARKER: &str = "__rcsc_comment!(";

impl Comments {
    /// A statement that stands for comment `text` until [`Comments::restore`].
    pub fn marker(&mut self, text: String) -> TokenStream {
        let n = proc_macro2::Literal::usize_unsuffixed(self.texts.len());
        self.texts.push(text);
        quote!(__rcsc_comment!(#n);)
    }

    fn restore(&self, printed: &str) -> String {
        let mut out = String::with_capacity(printed.len() + self.texts.len() * 80);
        for line in printed.lines() {
            let trimmed = line.trim_start();
            match trimmed
                .strip_prefix(MARKER)
                .and_then(|r| r.strip_suffix(");"))
                .and_then(|n| n.parse::<usize>().ok())
            {
                Some(n) => {
                    let indent = &line[..line.len() - trimmed.len()];
                    out.push_str(indent);
                    out.push_str("//");
                    if !self.texts[n].is_empty() {
                        out.push(' ');
                        out.push_str(&self.texts[n]);
                    }
                }
                None => out.push_str(line),
            }
            out.push('\n');
        }
        out
    }
}

/// The generated Rust of one plan set, as the text of `rust/<system>.rs`.
pub fn system_module(ir: &Ir, options: &crate::Options) -> String {
    let mut names = names::Names::new(ir);
    // Instances of one controller type share its module (LANGUAGE.md §8).
    let sharing = instances::Sharing::of(ir);
    for g in &sharing.groups {
        for &m in &g.members {
            names.ctrls[m].shared = true;
        }
    }
    let type_modules = instances::type_modules(&names, &sharing);
    let mut comments = Comments { texts: Vec::new() };
    let conversions = if options.driver {
        driver::type_conversions(ir, &names)
    } else {
        TokenStream::new()
    };
    // A distributed set's types travel over the bridge: serde through the
    // runtime's re-export, whatever `options.serde` says.
    let serde = match &options.serde {
        _ if names.wire => Some(types::SerdeDerive {
            attrs: schema::derives(&names),
            feature: None,
        }),
        crate::SerdeDerives::Off => None,
        crate::SerdeDerives::Always => Some(types::SerdeDerive {
            attrs: quote!(#[derive(::serde::Serialize, ::serde::Deserialize)]),
            feature: None,
        }),
        crate::SerdeDerives::Feature(name) => Some(types::SerdeDerive {
            attrs: quote!(#[cfg_attr(feature = #name, derive(::serde::Serialize, ::serde::Deserialize))]),
            feature: Some(name.clone()),
        }),
    };
    let types = types::module(ir, &names, serde.as_ref(), conversions);
    let controllers: Vec<TokenStream> = (0..ir.controllers.len())
        .map(|ci| {
            let Some(g) = sharing.group_of[ci] else {
                let extra = if options.driver {
                    driver::controller_driver(ir, &names, ci)
                } else {
                    TokenStream::new()
                };
                return controller::module(ir, &names, ci, &mut comments, extra, None);
            };
            let group = &sharing.groups[g];
            let mut out = TokenStream::new();
            if group.members[0] == ci {
                let shared = instances::type_names(
                    ir,
                    &names,
                    &sharing,
                    &type_modules,
                    ci,
                    Some(quote!(self.inst.params)),
                );
                let extra = if options.driver {
                    driver::driver_parts(ir, &shared, ci, driver::DriverPart::TypeCommand)
                } else {
                    TokenStream::new()
                };
                let ty = controller::TypeModule {
                    ty: &group.ty,
                    group,
                };
                out.extend(controller::module(
                    ir,
                    &shared,
                    ci,
                    &mut comments,
                    extra,
                    Some(&ty),
                ));
            }
            out.extend(instances::instance_module(
                ir,
                &names,
                &sharing,
                &type_modules,
                ci,
                options.driver,
            ));
            out
        })
        .collect();
    let mut system = system::system(ir, &names);
    if options.driver {
        system.extend(driver::set_driver(ir, &names));
        system.extend(system_driver::system_driver(ir, &names));
    }
    let system_ident = crate::ident::ident(&crate::ident::snake(&ir.system));
    let doc = format!(" The `{}` plan set, generated by rcsc.", ir.system);
    let tokens = quote! {
        #[doc = #doc]
        pub mod #system_ident {
            // Conditions are the plan's own, verbatim: redundant or duplicated
            // logic in a plan is the plan's (rcsc's checks report what matters,
            // e.g. `shadowed_row`) and must not fail the user's clippy run.
            // `System` has one type parameter per controller with hooks, so
            // its types grow with the plan set (`type_complexity`). A
            // negated float comparison is the plan's way to include NaN
            // (`!(x < 0.0)` holds for NaN; `x >= 0.0` does not).
            #![allow(
                unused_comparisons,
                clippy::nonminimal_bool,
                clippy::overly_complex_bool_expr,
                clippy::eq_op,
                clippy::redundant_comparisons,
                clippy::double_comparisons,
                clippy::ifs_same_cond,
                clippy::identity_op,
                clippy::erasing_op,
                clippy::absurd_extreme_comparisons,
                clippy::manual_range_contains,
                clippy::approx_constant,
                clippy::type_complexity,
                clippy::neg_cmp_op_on_partial_ord
            )]
            use ::rcs_runtime as rt;
            #types
            #(#controllers)*
            #system
        }
    };
    let file: syn::File = match syn::parse2(tokens) {
        Ok(f) => f,
        Err(e) => panic!(
            "rcsc generated tokens that do not parse as Rust ({e}); this is a bug in rcs-codegen"
        ),
    };
    let printed = prettyplease::unparse(&file);
    let sources: Vec<&str> = ir.files.iter().map(|f| f.as_str()).collect();
    format!(
        "// {GENERATED} from {}. Do not edit.\n{}",
        sources.join(", "),
        comments.restore(&printed)
    )
}

#[cfg(test)]
mod tests {
    use crate::{Options, SerdeDerives};

    fn rust(options: &Options) -> String {
        let set = rcs_dsl::PlanSet::from_texts(
            "t",
            [(
                "t.rcs",
                "enum Mode { Off, On }\nbuffer Small { m: Mode, xs: [u8; 32] }\nbuffer Big { xs: [u8; 33], grid: [[u8; 40]; 3] }\n\
                 controller A {\n    reads small: Small\n    reads big: Big\n    command GO\n    plan GO {\n        \
                 *0 when new_command && small.m == Mode::On && big.xs[0] == small.xs[0] -> Done\n    }\n}\n",
            )],
            None,
        );
        let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
            .ir
            .expect("clean");
        super::system_module(&ir, options)
    }

    /// The attribute line right above `pub <kind> <name>` (skipping docs).
    fn attrs_of(text: &str, item: &str) -> Vec<String> {
        let lines: Vec<&str> = text.lines().collect();
        let at = lines
            .iter()
            .position(|l| l.trim_start().starts_with(item))
            .unwrap_or_else(|| panic!("{item} in\n{text}"));
        lines[..at]
            .iter()
            .rev()
            .take_while(|l| l.trim_start().starts_with("#["))
            .map(|l| l.trim().to_string())
            .collect()
    }

    #[test]
    fn serde_derives_follow_the_option_and_long_arrays_go_through_serde_array() {
        let off = rust(&Options::default());
        assert!(!off.contains("serde"));

        let always = rust(&Options {
            serde: SerdeDerives::Always,
            ..Options::default()
        });
        let derive = "#[derive(::serde::Serialize, ::serde::Deserialize)]";
        assert!(attrs_of(&always, "pub enum Mode").contains(&derive.to_string()));
        assert!(attrs_of(&always, "pub struct Small").contains(&derive.to_string()));
        assert!(attrs_of(&always, "pub struct Big").contains(&derive.to_string()));
        // Arrays serde handles itself get no attribute; longer ones (or
        // arrays of them) a codec of `rcs_runtime::serde_array`.
        // Arrays serde handles itself get no attribute; longer ones (or
        // arrays of them) a codec of `rcs_runtime::serde_array`. Compared
        // without whitespace: rustfmt breaks long attributes.
        let squeeze = |t: &str| t.split_whitespace().collect::<String>();
        let always = squeeze(&always);
        assert!(always.contains("{pubm:super::types::Mode,pubxs:[u8;32],}"));
        let leaf = "::rcs_runtime::serde_array::Leaf<u8>";
        let long = format!(
            r#"#[serde(with="::rcs_runtime::serde_array::Array::<{leaf},33>")]pubxs:[u8;33],"#
        );
        assert!(always.contains(&long), "{always}");
        let nested = format!(
            r#"#[serde(with="::rcs_runtime::serde_array::Array::<::rcs_runtime::serde_array::Array<{leaf},40>,3>")]pubgrid:[[u8;40];3],"#
        );
        assert!(always.contains(&nested), "{always}");

        let feature = rust(&Options {
            serde: SerdeDerives::Feature("wire".into()),
            ..Options::default()
        });
        assert!(attrs_of(&feature, "pub struct Small").contains(
            &"#[cfg_attr(feature = \"wire\", derive(::serde::Serialize, ::serde::Deserialize))]"
                .to_string()
        ));
        // The field's attribute sits behind the same feature as the derive.
        let gated = format!(
            r#"#[cfg_attr(feature="wire",serde(with="::rcs_runtime::serde_array::Array::<{leaf},33>"))]pubxs:[u8;33],"#
        );
        assert!(squeeze(&feature).contains(&gated), "{feature}");
    }

    #[test]
    fn the_driver_is_emitted_only_when_asked() {
        let off = rust(&Options::default());
        assert!(!off.contains("Driven") && !off.contains("new_driver"));
        let on = rust(&Options {
            driver: true,
            ..Options::default()
        });
        assert!(on.contains("impl ::rcs_runtime::driver::Driven for Driver"));
        assert!(on.contains("pub fn new_driver("));
        assert!(on.contains("impl ::rcs_runtime::driver::FromValue for Big"));
    }

    #[test]
    fn doc_comments_reach_the_rust_items_they_document() {
        let set = rcs_dsl::PlanSet::from_texts(
            "t",
            [(
                "t.rcs",
                "buffer B { x: f64 }\n\
                 /// Controller A.\n\
                 controller A \"Title\" {\n\
                 /// Read doc.\n    reads b: B\n\
                 /// Write doc.\n    writes c: B\n\
                 command GO(\n        /// Param doc.\n        speed: f64,\n    )\n\
                 hook h(\n        /// Hook param doc.\n        n: f64,\n    )\n\
                 /// Plan doc.\n    plan GO {\n\
                 /// Row doc.\n        *0 when new_command -> Done { c.x = cmd.speed; h(b.x) }\n    }\n}\n",
            )],
            None,
        );
        let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
            .ir
            .expect("clean");
        let text = super::system_module(&ir, &crate::Options::default());
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        let before = |doc: &str, item: &str| {
            assert!(
                lines
                    .windows(2)
                    .any(|w| w[0] == doc && w[1].starts_with(item)),
                "no `{doc}` right above `{item}` in\n{text}"
            );
        };
        before("/// Read doc.", "pub b: super::types::B");
        before("/// Write doc.", "pub c: super::types::B");
        before("/// Param doc.", "speed: f64");
        before("/// - `n`: Hook param doc.", "fn h(");
        before("/// Plan doc.", "#[derive");
        before("/// Plan doc.", "fn plan_go(");
        before("// Row doc.", "// E0: *0 when new_command -> Done");
        // The controller's doc comment stands for its title.
        before("/// Controller A.", "pub mod a {");
        assert!(!text.contains("`A`: Title."));
    }

    #[test]
    fn the_hooks_and_system_types_do_not_depend_on_file_names() {
        let zed = "controller Z {\n    command GO\n    hook z() -> bool\n    plan GO { *0 when new_command && z() -> Done }\n}\n";
        let ant = "controller A {\n    command GO\n    hook a() -> bool\n    plan GO { *0 when new_command && a() -> Done }\n}\n";
        let api = |files: [(&str, &str); 2]| -> Vec<String> {
            let set = rcs_dsl::PlanSet::from_texts("t", files, None);
            let ir = rcs_dsl::check(&set, &rcs_dsl::Options::default())
                .ir
                .expect("clean");
            super::system_module(&ir, &crate::Options::default())
                .lines()
                .map(str::trim)
                .filter(|l| {
                    l.starts_with("pub struct Hooks")
                        || l.starts_with("pub struct System")
                        || l.starts_with("impl<")
                })
                .map(String::from)
                .collect()
        };
        let one = api([("1.rcs", zed), ("2.rcs", ant)]);
        let other = api([("2.rcs", ant), ("9.rcs", zed)]);
        assert!(
            one.contains(&"pub struct Hooks<AHooks, ZHooks> {".to_string()),
            "{one:?}"
        );
        assert_eq!(one, other);
    }
}
