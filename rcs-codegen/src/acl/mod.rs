//! IR → each process's access-control policy (Zenoh `access_control` and
//! `low_pass_filter`), for a distributed plan set.
//!
//! Where it sits: a back end beside `rust/process.rs`, which embeds the
//! policy of every process in the generated `System::process`, and beside
//! the writer's `zenoh/PROCESS.json5` files (a whole Zenoh configuration per
//! process, for tools that are not rcsc's). The policy follows from the plan
//! set alone, which is why rcsc can write it and no hand-written policy
//! needs to exist:
//!
//! * every other process is a subject identified by its certificate's
//!   common name (its process name); the operator is the subject
//!   `operator`;
//! * a process may **put** to process Q exactly the buffers it writes and Q
//!   reads (its controllers' status buffers, their `writes` buffers, the
//!   command buffers of the subordinates they supervise, its `inputs:`),
//!   and may **subscribe** at Q exactly to the buffers Q writes and it
//!   reads; what Q may put to it and subscribe at it is the mirror image;
//! * the operator may put the command buffers of the roots that run in
//!   the process and subscribe to the status buffers of its controllers;
//! * the operator (and no one else) may subscribe to the process's console
//!   figures (`rcs/SYSTEM/_console/PROCESS/figures`) and put executive
//!   controls (pause, step, resume) on `rcs/SYSTEM/_console/PROCESS/control`
//!   (the keys of `rcs_runtime::bridge::console`);
//! * everything else is denied (`default_permission: deny`): a wildcard
//!   subscription such as `rcs/**`, a put to any other key, queries,
//!   liveliness;
//! * every put is also refused by size above the longest encoding of its
//!   buffer's type (`low_pass_filter`), so a flood of large junk costs the
//!   receiver no decoding.
//!
//! The operator's own program gets [`operator_policy`], the mirror image.
//!
//! Deterministic: rules, subjects and keys come out in placement order.

use rcs_dsl::ir::{Ir, Type};
use rcs_dsl::placement::{BufferKind, Placement};
use serde_json::{json, Value};

/// The subject name (certificate common name) of the operator: the
/// console, or any program commanding the roots of a distributed set.
pub const OPERATOR: &str = "operator";

/// The policy of process `process` (index into `placement.processes`) as a
/// JSON object with the keys `access_control` and `low_pass_filter`.
pub fn policy(ir: &Ir, placement: &Placement, process: usize) -> Value {
    let key = |b: &str| format!("rcs/{}/{}", ir.system, b);
    let mut acl = Acl::default();
    let mut filters: Vec<Value> = Vec::new();
    // Peer processes.
    for (q, peer) in placement.processes.iter().enumerate() {
        if q == process {
            continue;
        }
        let to_peer: Vec<String> = placement
            .crossings
            .iter()
            .filter(|x| x.writer == process && x.readers.contains(&q))
            .map(|x| key(&buffer_name(ir, &x.kind)))
            .collect();
        let from_peer: Vec<String> = placement
            .crossings
            .iter()
            .filter(|x| x.writer == q && x.readers.contains(&process))
            .map(|x| key(&buffer_name(ir, &x.kind)))
            .collect();
        let ids: Vec<String> = [
            acl.allow(
                format!("{peer}_may_subscribe"),
                "ingress",
                "declare_subscriber",
                to_peer.clone(),
            ),
            acl.allow(format!("put_to_{peer}"), "egress", "put", to_peer),
            acl.allow(
                format!("{peer}_may_put"),
                "ingress",
                "put",
                from_peer.clone(),
            ),
            acl.allow(
                format!("subscribe_at_{peer}"),
                "egress",
                "declare_subscriber",
                from_peer,
            ),
        ]
        .into_iter()
        .flatten()
        .collect();
        acl.grant(peer, ids);
    }
    // The operator: root commands in, statuses out.
    let here: Vec<usize> = (0..ir.controllers.len())
        .filter(|&c| placement.ctrl_process[c] == process)
        .collect();
    let root_commands: Vec<String> = here
        .iter()
        .filter(|&&c| ir.controllers[c].supervisor.is_none())
        .map(|&c| key(&format!("{}.command", ir.controllers[c].name)))
        .collect();
    let statuses: Vec<String> = here
        .iter()
        .map(|&c| key(&format!("{}.status", ir.controllers[c].name)))
        .collect();
    let name = &placement.processes[process];
    let figures = vec![console_key(ir, name, "figures")];
    let control = vec![console_key(ir, name, "control")];
    let ids: Vec<String> = [
        acl.allow(
            format!("commands_from_{OPERATOR}"),
            "egress",
            "declare_subscriber",
            root_commands.clone(),
        ),
        acl.allow(
            format!("{OPERATOR}_may_command"),
            "ingress",
            "put",
            root_commands,
        ),
        acl.allow(
            format!("{OPERATOR}_may_subscribe"),
            "ingress",
            "declare_subscriber",
            statuses.clone(),
        ),
        acl.allow(format!("statuses_to_{OPERATOR}"), "egress", "put", statuses),
        acl.allow(
            format!("{OPERATOR}_may_watch"),
            "ingress",
            "declare_subscriber",
            figures.clone(),
        ),
        acl.allow(format!("figures_to_{OPERATOR}"), "egress", "put", figures),
        acl.allow(
            format!("controls_from_{OPERATOR}"),
            "egress",
            "declare_subscriber",
            control.clone(),
        ),
        acl.allow(
            format!("{OPERATOR}_may_control"),
            "ingress",
            "put",
            control.clone(),
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    acl.grant(OPERATOR, ids);
    // Size limits on what may arrive.
    for x in placement
        .crossings
        .iter()
        .filter(|x| x.readers.contains(&process))
    {
        filters.push(json!({
            "id": format!("size_{}", buffer_name(ir, &x.kind)).replace('.', "_"),
            "flows": ["ingress"],
            "messages": ["put"],
            "key_exprs": [key(&buffer_name(ir, &x.kind))],
            "size_limit": wire_bound(ir, &x.kind),
        }));
    }
    filters.push(json!({
        "id": "size_console_control",
        "flows": ["ingress"],
        "messages": ["put"],
        "key_exprs": control,
        "size_limit": CONTROL_BOUND,
    }));
    let mut subjects: Vec<Value> = placement
        .processes
        .iter()
        .enumerate()
        .filter(|(q, _)| *q != process)
        .map(|(_, p)| json!({ "id": p, "cert_common_names": [p] }))
        .collect();
    subjects.push(json!({ "id": OPERATOR, "cert_common_names": [OPERATOR] }));
    json!({
        "access_control": acl.into_json(subjects),
        "low_pass_filter": filters,
    })
}

/// The policy of the operator (a console, or any program commanding the
/// roots from a process of its own): per process, it may put the command
/// buffers of the roots that run there and subscribe to the status buffers
/// of that process's controllers, and nothing else.
pub fn operator_policy(ir: &Ir, placement: &Placement) -> Value {
    let key = |b: String| format!("rcs/{}/{}", ir.system, b);
    let mut acl = Acl::default();
    for (p, process) in placement.processes.iter().enumerate() {
        let here = (0..ir.controllers.len()).filter(|&c| placement.ctrl_process[c] == p);
        let commands: Vec<String> = here
            .clone()
            .filter(|&c| ir.controllers[c].supervisor.is_none())
            .map(|c| key(format!("{}.command", ir.controllers[c].name)))
            .collect();
        let statuses: Vec<String> = here
            .map(|c| key(format!("{}.status", ir.controllers[c].name)))
            .collect();
        let figures = vec![console_key(ir, process, "figures")];
        let control = vec![console_key(ir, process, "control")];
        let mut ids = Vec::new();
        for (id, flow, message, keys) in [
            (
                format!("{process}_may_subscribe"),
                "ingress",
                "declare_subscriber",
                &commands,
            ),
            (format!("command_{process}"), "egress", "put", &commands),
            (
                format!("statuses_of_{process}"),
                "ingress",
                "put",
                &statuses,
            ),
            (
                format!("subscribe_at_{process}"),
                "egress",
                "declare_subscriber",
                &statuses,
            ),
            (format!("figures_of_{process}"), "ingress", "put", &figures),
            (
                format!("watch_{process}"),
                "egress",
                "declare_subscriber",
                &figures,
            ),
            (
                format!("{process}_takes_controls"),
                "ingress",
                "declare_subscriber",
                &control,
            ),
            (format!("control_{process}"), "egress", "put", &control),
        ] {
            ids.extend(acl.allow(id, flow, message, keys.clone()));
        }
        acl.grant(process, ids);
    }
    let subjects: Vec<Value> = placement
        .processes
        .iter()
        .map(|p| json!({ "id": p, "cert_common_names": [p] }))
        .collect();
    json!({ "access_control": acl.into_json(subjects) })
}

/// The console key `rcs/SYSTEM/_console/PROCESS/WHAT` (`figures` or
/// `control`), as `rcs_runtime::bridge::console` names them.
fn console_key(ir: &Ir, process: &str, what: &str) -> String {
    format!("rcs/{}/_console/{process}/{what}", ir.system)
}

/// The size limit of an executive control: the runtime's
/// `console::CONTROL_MAX_LEN` (a wire header of 297 bytes, an executive
/// name of up to 255, 32 for the action) with the same margin as buffers.
const CONTROL_BOUND: u64 = 297 + 255 + 32 + 64;

/// Zenoh's `access_control` as it is built: allow rules, and which subject
/// holds which (everything else denied).
#[derive(Default)]
struct Acl {
    rules: Vec<Value>,
    policies: Vec<Value>,
}

impl Acl {
    /// An allow rule `id` for `message` on `flow` over `keys`; `None` (no
    /// rule) when there are no keys.
    fn allow(
        &mut self,
        id: String,
        flow: &str,
        message: &str,
        keys: Vec<String>,
    ) -> Option<String> {
        if keys.is_empty() {
            return None;
        }
        self.rules.push(json!({
            "id": id,
            "flows": [flow],
            "messages": [message],
            "permission": "allow",
            "key_exprs": keys,
        }));
        Some(id)
    }

    /// Give `subject` the rules `ids` (nothing when there are none).
    fn grant(&mut self, subject: &str, ids: Vec<String>) {
        if !ids.is_empty() {
            self.policies
                .push(json!({ "subjects": [subject], "rules": ids }));
        }
    }

    fn into_json(self, subjects: Vec<Value>) -> Value {
        json!({
            "enabled": true,
            "default_permission": "deny",
            "rules": self.rules,
            "subjects": subjects,
            "policies": self.policies,
        })
    }
}

/// A whole Zenoh configuration of process `process` (JSON5 with a header
/// comment): peer mode, scouting off, mutual TLS with the files `rcsc
/// certs` writes (paths relative to where the process runs: edit them for
/// a deployment), and the policy. `System::process` builds the same from
/// its `BridgeConfig`; this file is for Zenoh tools and reviews.
pub fn zenoh_config_file(ir: &Ir, placement: &Placement, process: usize) -> String {
    let name = &placement.processes[process];
    config_file(ir, name, policy(ir, placement, process))
}

/// The whole Zenoh configuration of the operator (`zenoh/operator.json5`).
pub fn operator_config_file(ir: &Ir, placement: &Placement) -> String {
    config_file(ir, OPERATOR, operator_policy(ir, placement))
}

fn config_file(ir: &Ir, name: &str, policy: Value) -> String {
    let Value::Object(policy) = policy else {
        unreachable!("policies are objects")
    };
    let mut config = json!({
        "mode": "peer",
        "scouting": { "multicast": { "enabled": false }, "gossip": { "enabled": false } },
        "transport": { "link": {
            "protocols": ["tls"],
            "tls": {
                "root_ca_certificate": "certs/ca.pem",
                "listen_certificate": format!("certs/{name}.pem"),
                "listen_private_key": format!("certs/{name}.key"),
                "connect_certificate": format!("certs/{name}.pem"),
                "connect_private_key": format!("certs/{name}.key"),
                "enable_mtls": true,
                "verify_name_on_connect": false,
            },
        } },
    });
    if let Value::Object(map) = &mut config {
        map.extend(policy);
    }
    let body = serde_json::to_string_pretty(&config).unwrap_or_default();
    format!(
        "// {} — Zenoh configuration of `{name}` in system `{}`.\n\
         // Access control from the plan set: default deny; each peer may put and\n\
         // subscribe only to the buffers the plan set says it writes and reads.\n\
         // Listen/connect endpoints are the deployment's: add `listen`/`connect`.\n\
         {body}\n",
        crate::GENERATED,
        ir.system
    )
}

/// The Global Memory name of a crossing buffer.
pub fn buffer_name(ir: &Ir, kind: &BufferKind) -> String {
    match kind {
        BufferKind::Declared(b) => ir.buffers[b.index()].name.clone(),
        BufferKind::Command(c) => format!("{}.command", ir.controllers[c.index()].name),
        BufferKind::Status(c) => format!("{}.status", ir.controllers[c.index()].name),
        BufferKind::StatusFields(c) => {
            format!("{}.status_fields", ir.controllers[c.index()].name)
        }
    }
}

/// An upper bound of a sample's payload for a buffer of this kind: the
/// header (four varints and a process name of up to 255 bytes) and the
/// longest postcard encoding of the value.
fn wire_bound(ir: &Ir, kind: &BufferKind) -> u64 {
    const HEADER: u64 = 4 * 10 + 2 + 255;
    let value = match kind {
        BufferKind::Declared(b) => {
            let ty = &ir.buffer_types[ir.buffers[b.index()].ty.index()];
            ty.fields.iter().map(|f| type_bound(ir, &f.ty)).sum()
        }
        // serial (5), epoch (5), verb tag (5), the largest verb's parameters.
        BufferKind::Command(c) => {
            15 + ir.controllers[c.index()]
                .commands
                .iter()
                .map(|cmd| {
                    cmd.params
                        .iter()
                        .map(|p| type_bound(ir, &p.ty))
                        .sum::<u64>()
                })
                .max()
                .unwrap_or(0)
        }
        // Serial and epoch (5 each), four u16 (3 each).
        BufferKind::Status(_) => 22,
        BufferKind::StatusFields(c) => ir.controllers[c.index()]
            .status_fields()
            .map(|(_, v)| type_bound(ir, &v.ty))
            .sum(),
    };
    // Room for fields the runtime adds to the handshake buffers.
    HEADER + value + 64
}

fn type_bound(ir: &Ir, ty: &Type) -> u64 {
    match ty {
        Type::Bool | Type::Unit => 1,
        Type::Int(_) | Type::Float(_) => 10,
        Type::Enum(_) | Type::Status(_) | Type::ErrorCode(_) => 5,
        Type::Buffer(b) => ir.buffer_types[b.index()]
            .fields
            .iter()
            .map(|f| type_bound(ir, &f.ty))
            .sum(),
        Type::Array(elem, n) => u64::from(*n).saturating_mul(type_bound(ir, elem)),
    }
}

#[cfg(test)]
mod tests;
