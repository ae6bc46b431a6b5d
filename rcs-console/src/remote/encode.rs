//! A root's command as the console sends it over Zenoh: the catalog's verb
//! and checked arguments → [`GenericCommand`] → the bridge's wire sample
//! for the root's command buffer, under the schema hash the root's process
//! published ([`RootCommand`](rcs_runtime::bridge::console::RootCommand)).
//!
//! The console has no generated types; the runtime's [`GenericCommand`]
//! serializes as a generated `Command` enum does, given each argument in
//! its declared type — which this module picks from the catalog's
//! [`ParamType`]. The split example's tests compare the bytes with the
//! generated `sm::Command`'s.

use rcs_runtime::bridge::console::command::{encode_command, GenericCommand, WireArg};

use crate::catalog::{ArgValue, Catalog, ParamType};

/// An argument in its declared type, or why it cannot be sent.
pub fn wire_arg(ty: &ParamType, value: &ArgValue) -> Result<WireArg, String> {
    let int = |v: i128| -> Result<WireArg, String> {
        let ParamType::Int(name, ..) = ty else {
            return Err(format!("an integer for a {}", ty.name()));
        };
        let out = |ok: Option<WireArg>| ok.ok_or(format!("{v} is out of {name}'s range"));
        match *name {
            "u8" => out(u8::try_from(v).ok().map(WireArg::U8)),
            "u16" => out(u16::try_from(v).ok().map(WireArg::U16)),
            "u32" => out(u32::try_from(v).ok().map(WireArg::U32)),
            "u64" => out(u64::try_from(v).ok().map(WireArg::U64)),
            "i8" => out(i8::try_from(v).ok().map(WireArg::I8)),
            "i16" => out(i16::try_from(v).ok().map(WireArg::I16)),
            "i32" => out(i32::try_from(v).ok().map(WireArg::I32)),
            "i64" => out(i64::try_from(v).ok().map(WireArg::I64)),
            other => Err(format!("the console cannot send a {other}")),
        }
    };
    match (ty, value) {
        (ParamType::Bool, ArgValue::Bool(b)) => Ok(WireArg::Bool(*b)),
        (ParamType::Int(..), ArgValue::Int(v)) => int(*v),
        // The value was parsed as f64; an f32 parameter takes it rounded,
        // as `as f32` in the generated code would.
        (ParamType::Float("f32"), ArgValue::Float(v)) => Ok(WireArg::F32(*v as f32)),
        (ParamType::Float(_), ArgValue::Float(v)) => Ok(WireArg::F64(*v)),
        (ParamType::Enum(name, variants), ArgValue::Enum(v)) => variants
            .iter()
            .position(|x| x == v)
            .and_then(|i| u32::try_from(i).ok())
            .map(WireArg::Enum)
            .ok_or_else(|| format!("`{v}` is not a {name}")),
        (ty, v) => Err(format!("{v:?} is not a {}", ty.name())),
    }
}

/// `root`'s verb `verb` with `args` (already checked against the catalog)
/// as a [`GenericCommand`].
pub fn generic_command(
    catalog: &Catalog,
    root: &str,
    verb: &str,
    args: &[ArgValue],
) -> Result<GenericCommand, String> {
    let c = catalog
        .controller(root)
        .ok_or_else(|| format!("no controller `{root}`"))?;
    let (index, v) = c
        .verbs
        .iter()
        .enumerate()
        .find(|(_, v)| v.name == verb)
        .ok_or_else(|| format!("{root} has no verb `{verb}`"))?;
    if v.params.len() != args.len() {
        return Err(format!(
            "{verb} takes {} parameter(s), {} given",
            v.params.len(),
            args.len()
        ));
    }
    let args = v
        .params
        .iter()
        .zip(args)
        .map(|((name, ty), a)| wire_arg(ty, a).map_err(|e| format!("{name}: {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(GenericCommand {
        verb: u16::try_from(index).map_err(|_| format!("{root} has too many verbs"))?,
        args,
    })
}

/// The identity of a command on the wire, as a [`SubordinateLink`] gives
/// it: serial, epoch, and the sender's stamps.
///
/// [`SubordinateLink`]: rcs_runtime::SubordinateLink
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stamps {
    /// The sender's instance (one per console session).
    pub instance: u64,
    /// Commands sent by this sender so far, this one included (from 1).
    pub generation: u64,
    /// The command's serial.
    pub serial: u32,
    /// The command's epoch.
    pub epoch: u32,
}

/// The whole sample for `root`'s command buffer of schema `schema`.
pub fn encode_root_command(
    catalog: &Catalog,
    schema: u64,
    root: &str,
    verb: &str,
    args: &[ArgValue],
    stamps: Stamps,
) -> Result<Vec<u8>, String> {
    let command = generic_command(catalog, root, verb, args)?;
    encode_command(
        schema,
        stamps.instance,
        stamps.generation,
        stamps.serial,
        stamps.epoch,
        command,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_take_their_declared_types() {
        assert_eq!(
            wire_arg(&ParamType::Int("u8", 0, 255), &ArgValue::Int(200)),
            Ok(WireArg::U8(200))
        );
        assert_eq!(
            wire_arg(&ParamType::Int("i16", -32768, 32767), &ArgValue::Int(-5)),
            Ok(WireArg::I16(-5))
        );
        assert!(wire_arg(&ParamType::Int("u8", 0, 255), &ArgValue::Int(256)).is_err());
        assert_eq!(
            wire_arg(&ParamType::Float("f32"), &ArgValue::Float(1.5)),
            Ok(WireArg::F32(1.5))
        );
        assert_eq!(
            wire_arg(&ParamType::Float("f64"), &ArgValue::Float(1.5)),
            Ok(WireArg::F64(1.5))
        );
        let gear = ParamType::Enum("Gear".into(), vec!["LOW".into(), "HIGH".into()]);
        assert_eq!(
            wire_arg(&gear, &ArgValue::Enum("HIGH".into())),
            Ok(WireArg::Enum(1))
        );
        assert!(wire_arg(&gear, &ArgValue::Enum("MID".into())).is_err());
        assert!(wire_arg(&ParamType::Bool, &ArgValue::Float(1.0)).is_err());
        assert!(wire_arg(&ParamType::Other("[f64; 3]".into()), &ArgValue::Int(1)).is_err());
    }

    #[test]
    fn the_submarine_roots_verbs_by_index() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../plans/submarine");
        let catalog = Catalog::load(&path).expect("the submarine plan set");
        assert_eq!(
            generic_command(&catalog, "SM", "TRANSIT", &[ArgValue::Float(8.0)]),
            Ok(GenericCommand {
                verb: 1,
                args: vec![WireArg::F64(8.0)]
            })
        );
        assert_eq!(
            generic_command(&catalog, "SM", "INIT", &[]),
            Ok(GenericCommand {
                verb: 0,
                args: vec![]
            })
        );
        assert!(generic_command(&catalog, "SM", "DIVE", &[]).is_err());
        assert!(generic_command(&catalog, "SM", "TRANSIT", &[]).is_err());
    }
}
