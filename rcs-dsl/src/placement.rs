//! Placement: which process each CPU of the schedule runs in, and which
//! Global Memory buffers therefore cross from one process to another.
//!
//! Where it sits: the manifest parser calls [`check_process_name`] on each
//! `process:`; lowering calls [`lower_inputs`] for the `inputs:` lists; the
//! back ends (the Rust `System::process`, the hierarchy graph) ask
//! [`Placement::of`] for the processes and the crossing buffers. A plan set
//! whose CPUs all sit in one process (the default: no `process:` at all)
//! has one process named after the system and no crossings, and every back
//! end emits exactly what it did before placement existed.

use crate::diagnostic::{Code, Diagnostic, Diagnostics};
use crate::ir::{BufferId, Cpu, CtrlId, Ir};
use crate::manifest::CpuSpec;
use crate::source::Span;

/// The problem with a `process:` name, if any: it must be an identifier,
/// since it is typed on a command line and names a Rust string constant.
pub fn check_process_name(name: &str, span: Span) -> Option<Diagnostic> {
    let message = if name.is_empty() {
        "empty process name".to_string()
    } else if !(name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
    {
        format!("process name `{name}` is not an identifier")
    } else {
        return None;
    };
    Some(
        Diagnostic::error(
            Code::Placement,
            message,
            span,
            "the process this CPU runs in",
        )
        .with_help(
            "name the process with letters, digits and `_`, not starting with a digit \
                 (`process: servo`); leave `process:` out to run the CPU in the default process",
        ),
    )
}

/// Resolve each CPU's `inputs:` to buffers: external inputs (no controller
/// writes them), each listed once across the schedule.
pub(crate) fn lower_inputs(ir: &Ir, specs: &[CpuSpec], cpus: &mut [Cpu], diags: &mut Diagnostics) {
    let mut listed: Vec<Option<Span>> = vec![None; ir.buffers.len()];
    for (spec, cpu) in specs.iter().zip(cpus.iter_mut()) {
        for (name, span) in &spec.inputs {
            let Some(b) = ir.buffers.iter().position(|b| b.name == *name) else {
                let external: Vec<&str> = ir
                    .buffers
                    .iter()
                    .filter(|b| b.writer.is_none())
                    .map(|b| b.name.as_str())
                    .collect();
                diags.push(
                    Diagnostic::error(
                        Code::Placement,
                        format!("`inputs` names `{name}`, which is not a buffer"),
                        *span,
                        "unknown buffer",
                    )
                    .with_help(format!(
                        "the external inputs (buffers no controller writes) are: {}",
                        if external.is_empty() {
                            "none".to_string()
                        } else {
                            external.join(", ")
                        }
                    )),
                );
                continue;
            };
            if let Some(w) = ir.buffers[b].writer {
                diags.push(
                    Diagnostic::error(
                        Code::Placement,
                        format!(
                            "`inputs` names `{name}`, which controller `{}` writes",
                            ir.controllers[w.index()].name
                        ),
                        *span,
                        "not an external input",
                    )
                    .with_help(
                        "`inputs` lists buffers that hand-written code (a simulator, a driver) \
                         writes; a controller's buffers live where the controller runs",
                    ),
                );
                continue;
            }
            if let Some(first) = listed[b] {
                diags.push(
                    Diagnostic::error(
                        Code::Placement,
                        format!("input `{name}` is listed twice"),
                        *span,
                        "listed again here",
                    )
                    .with_secondary(first, "first listed here")
                    .with_help("an external input has one writer, in one process"),
                );
                continue;
            }
            listed[b] = Some(*span);
            cpu.inputs.push(BufferId(b as u32));
        }
    }
}

/// Who writes a crossing buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BufferKind {
    /// A `reads`/`writes` buffer (or an external input), by id.
    Declared(BufferId),
    /// Controller's command buffer (written by its supervisor).
    Command(CtrlId),
    /// Controller's status buffer.
    Status(CtrlId),
    /// Controller's status-fields buffer.
    StatusFields(CtrlId),
}

/// A buffer written in one process and read in others.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Crossing {
    pub kind: BufferKind,
    /// Index into [`Placement::processes`] of the writing process.
    pub writer: usize,
    /// Indexes of the reading processes other than the writer's, ascending.
    pub readers: Vec<usize>,
}

/// The processes of a plan set and the buffers that cross between them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Placement {
    /// Process names, in the order the schedule first names them.
    pub processes: Vec<String>,
    /// Each CPU's process (index into `processes`), in schedule order.
    pub cpu_process: Vec<usize>,
    /// Each controller's process.
    pub ctrl_process: Vec<usize>,
    /// The buffers written in one process and read in another, in buffer
    /// order, then controller order (command, status, status fields).
    pub crossings: Vec<Crossing>,
}

impl Placement {
    /// Compute the placement of `ir`.
    pub fn of(ir: &Ir) -> Placement {
        let mut processes: Vec<String> = Vec::new();
        let mut cpu_process = Vec::new();
        let mut ctrl_process = vec![0; ir.controllers.len()];
        for cpu in &ir.schedule {
            let name = ir.process_of(cpu);
            let p = match processes.iter().position(|p| p == name) {
                Some(p) => p,
                None => {
                    processes.push(name.to_string());
                    processes.len() - 1
                }
            };
            cpu_process.push(p);
            for c in &cpu.order {
                ctrl_process[c.index()] = p;
            }
        }
        if processes.is_empty() {
            processes.push(ir.system.clone());
        }
        let mut crossings = Vec::new();
        let mut cross =
            |kind: BufferKind, writer: usize, readers: &mut dyn Iterator<Item = usize>| {
                let mut rs: Vec<usize> = readers.filter(|r| *r != writer).collect();
                rs.sort_unstable();
                rs.dedup();
                if !rs.is_empty() {
                    crossings.push(Crossing {
                        kind,
                        writer,
                        readers: rs,
                    });
                }
            };
        for (b, buf) in ir.buffers.iter().enumerate() {
            let readers = buf.readers.iter().map(|r| ctrl_process[r.index()]);
            let writer = match buf.writer {
                Some(w) => Some(ctrl_process[w.index()]),
                None => input_writer(ir, &cpu_process, &ctrl_process, BufferId(b as u32)),
            };
            if let Some(w) = writer {
                cross(
                    BufferKind::Declared(BufferId(b as u32)),
                    w,
                    &mut readers.clone(),
                );
            }
        }
        for (c, ctrl) in ir.controllers.iter().enumerate() {
            let Some(sup) = ctrl.supervisor else { continue };
            let (here, above) = (ctrl_process[c], ctrl_process[sup.index()]);
            let id = CtrlId(c as u32);
            cross(BufferKind::Command(id), above, &mut std::iter::once(here));
            cross(BufferKind::Status(id), here, &mut std::iter::once(above));
            if ctrl.status_fields().next().is_some() {
                cross(
                    BufferKind::StatusFields(id),
                    here,
                    &mut std::iter::once(above),
                );
            }
        }
        Placement {
            processes,
            cpu_process,
            ctrl_process,
            crossings,
        }
    }

    /// Whether the plan set runs in more than one process.
    pub fn is_distributed(&self) -> bool {
        self.processes.len() > 1
    }

    /// The process an external input is written in (see [`Placement::of`]).
    pub fn input_process(&self, ir: &Ir, b: BufferId) -> Option<usize> {
        input_writer(ir, &self.cpu_process, &self.ctrl_process, b)
    }
}

/// The process that writes external input `b`: the one whose CPU lists it
/// in `inputs:`, else its first reader's (none if nothing reads it).
fn input_writer(
    ir: &Ir,
    cpu_process: &[usize],
    ctrl_process: &[usize],
    b: BufferId,
) -> Option<usize> {
    ir.schedule
        .iter()
        .zip(cpu_process)
        .find(|(cpu, _)| cpu.inputs.contains(&b))
        .map(|(_, p)| *p)
        .or_else(|| {
            ir.buffers[b.index()]
                .readers
                .first()
                .map(|r| ctrl_process[r.index()])
        })
}
