//! A plan set of `n` instances of one controller type (LANGUAGE.md §8),
//! and the same set written out by hand: one controller per instance, the
//! type's body copied with its bindings and parameter filled in. Both
//! expand to the same controllers; the benchmark compares what each costs
//! (`examples/instance_set.rs` writes them to disk).

use std::fmt::Write;

const HEADER: &str = "enum Mode { Off, Homing, Moving, Fault }
buffer AxisIo { position: f64, velocity: f64, homed: bool, fault: bool, mode: Mode }
buffer AxisOut { setpoint: f64, enable: bool, id: u16 }
";

/// The body of the axis, with `@IO@`, `@OUT@` and `@ID@` standing for its
/// bindings and its parameter.
const BODY: &str = "    reads @IO@: AxisIo
    writes @OUT@: AxisOut
    command HOME
    command MOVE(to: f64, speed: f64)
    command STOP
    status AT_GOAL
    error FAULTED, TIMEOUT
    var moves: u32 = 0
    hook trajectory(to: f64, speed: f64) -> f64
    plan HOME {
        E0: *0 when new_command -> S1 { @OUT@.enable = true; @OUT@.id = @ID@ }
        E1: *1 when @IO@.fault -> Error(FAULTED) { @OUT@.enable = false }
        E2: S1 when @IO@.homed -> Done
        E3: S1 when state_cycles > 500 -> Error(TIMEOUT)
    }
    plan MOVE {
        E0: *0 when new_command && @IO@.homed -> S1 { @OUT@.setpoint = trajectory(cmd.to, cmd.speed) }
        E1: *1 when new_command -> Error(FAULTED)
        E2: *2 when @IO@.fault -> Error(FAULTED) { @OUT@.enable = false }
        E3: S1 when @IO@.position > cmd.to - 0.01 && @IO@.position < cmd.to + 0.01 -> Done { moves += 1; report AT_GOAL }
        E4: S1 when state_cycles > 1000 -> Error(TIMEOUT)
        E5: S1 when true -> same { @OUT@.setpoint = trajectory(cmd.to, cmd.speed) }
    }
    plan STOP {
        E0: *0 when new_command -> Done { @OUT@.enable = false; @OUT@.setpoint = @IO@.position }
    }
";

/// `n` instances of `controller type Axis(id: u16)`.
pub fn instances(n: usize) -> String {
    let mut out = String::from(HEADER);
    let body = BODY
        .replace("@IO@", "io")
        .replace("@OUT@", "out")
        .replace("@ID@", "id");
    let _ = write!(
        out,
        "\n/// One axis, written once.\ncontroller type Axis(id: u16) {{\n{body}}}\n\n"
    );
    for i in 0..n {
        let _ = writeln!(
            out,
            "controller A{i} = Axis(id: {i}) {{ io: io{i}, out: out{i} }}"
        );
    }
    out
}

/// The same `n` axes, each written out.
pub fn copies(n: usize) -> String {
    let mut out = String::from(HEADER);
    for i in 0..n {
        let body = BODY
            .replace("@IO@", &format!("io{i}"))
            .replace("@OUT@", &format!("out{i}"))
            .replace("@ID@", "id");
        let _ = write!(
            out,
            "\n/// One axis, written once.\ncontroller A{i} {{\n    const id: u16 = {i}\n{body}}}\n"
        );
    }
    out
}
