#!/usr/bin/env python3
"""Equivalent state machines for the build-cost comparison of issue 30.

generate.py OUT N [--rcsc PATH] [--build-opt LEVEL]

writes three crates under OUT, each holding N copies of one machine of
5 states and 10 rows (rcsc counts its entry row among the 10; the others
start in S1), driven by the same event sequence and printing the same
checksum, so the three are shown equivalent before they are timed:

  OUT/rcsc     a plan set under plans/, compiled by build.rs with
               rcs_codegen::Config, driven through the generated System
  OUT/smlang   smlang 0.8's statemachine! macro, one module per machine
  OUT/statig   statig 0.4's #[state_machine], one module per machine

The machine: events 1..3; TABLE lists (from, event, to, add). An event no
row of the current state takes leaves the machine where it is. `count`
adds `add` on every transition; the checksum is the sum over machines of
state_number * 1000 + count after the sequence.

All three crates get the same `[profile.release.build-override]
opt-level = LEVEL` (default 1; 0 leaves cargo's unoptimised default), so
that rcsc's build script and the others' proc macros run alike.
"""

import os
import sys

TABLE = [
    (1, 1, 2, 1), (1, 2, 3, 2),
    (2, 2, 3, 1), (2, 3, 1, 3),
    (3, 3, 4, 1), (3, 1, 2, 2),
    (4, 1, 5, 1), (4, 2, 1, 2),
    (5, 3, 1, 1),
]
STATES = 5


def events(i, n=64):
    """Machine i's event sequence: deterministic, different per machine."""
    x = 2654435761 * (i + 1) & 0xFFFFFFFF
    out = []
    for _ in range(n):
        x = (x * 1103515245 + 12345) & 0x7FFFFFFF
        out.append(1 + (x >> 16) % 3)
    return out


def expected(n):
    """The checksum every crate must print, computed here from TABLE."""
    total = 0
    for i in range(n):
        state, count = 1, 0
        for e in events(i):
            for (f, ev, to, add) in TABLE:
                if f == state and ev == e:
                    state, count = to, count + add
                    break
        total += state * 1000 + count
    return total


# Build scripts and proc macros run in cargo's build-override profile, which
# is unoptimised by default: rcsc's build.rs (rcs-codegen) and smlang's and
# statig's proc macros alike. The bench gives all three crates the same
# optimised profile (what rcs-codegen's docs recommend), so that none pays
# for an unoptimised code generator and the comparison stays fair. Their
# dependencies are built once; the timed rebuild does not compile them.
BUILD_OVERRIDE = "\n[profile.release.build-override]\nopt-level = %d\n"


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def events_rs(n):
    rows = ",\n".join("    &[%s]" % ", ".join(str(e) for e in events(i)) for i in range(n))
    return "pub const EVENTS: [&[u8]; %d] = [\n%s,\n];\n" % (n, rows)


def rcsc_crate(out, n, rcsc, build_override):
    plans = []
    for i in range(n):
        rows = ["        *0 when new_command -> S1"]
        for (f, ev, to, add) in TABLE:
            rows.append("        S%d when e%d.code == %d -> S%d { count += %d }" % (f, i, ev, to, add))
        plans.append(
            "controller M%d {\n    reads e%d: Ev\n    command RUN\n    var count: u32 = 0\n"
            "    #[allow(no_done)]\n    plan RUN {\n%s\n    }\n}\n" % (i, i, "\n".join(rows))
        )
    plans.append("buffer Ev { code: u8 }\n")
    write(os.path.join(out, "plans/machines/machines.rcs"), "\n".join(plans))
    write(os.path.join(out, "Cargo.toml"),
          "[package]\nname = \"machines-rcsc\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n"
          "[dependencies]\nrcs-runtime = { path = \"%s/rcs-runtime\" }\n\n"
          "[build-dependencies]\nrcs-codegen = { path = \"%s/rcs-codegen\" }\n\n[workspace]\n%s"
          % (rcsc, rcsc, build_override))
    write(os.path.join(out, "build.rs"),
          "fn main() -> Result<(), Box<dyn std::error::Error>> {\n"
          "    rcs_codegen::Config::new().graphs(false).compile(\"plans/machines\")?;\n    Ok(())\n}\n")
    feed = []
    for i in range(n):
        feed.append(
            "    system.inputs.e%d.write(types::Ev { code: EVENTS[%d].get(k).copied().unwrap_or(0) }, k as u64 + 1);" % (i, i))
    cmd = "\n".join("    system.operators.m%d.command(m%d::Command::Run);" % (i, i) for i in range(n))
    sums = "\n".join(
        "    if let Some(c) = system.m%d() { sum += state_number(c.state_name()) * 1000 + u64::from(c.data().vars.count); }" % i
        for i in range(n))
    write(os.path.join(out, "src/main.rs"),
          "rcs_runtime::include_plans!(\"machines\");\nuse machines::*;\nmod events;\nuse events::EVENTS;\n\n"
          "fn state_number(name: Option<&str>) -> u64 {\n"
          "    name.and_then(|s| s.strip_prefix('S')).and_then(|s| s.parse().ok()).unwrap_or(0)\n}\n\n"
          "fn main() {\n    let mut system = System::new(Hooks::default()).expect(\"system\");\n%s\n"
          "    system.run_cycles(1).expect(\"entry\");\n"
          "    for k in 0..64 {\n%s\n        system.run_cycles(1).expect(\"cycle\");\n    }\n"
          "    let mut sum = 0u64;\n%s\n    println!(\"checksum {sum}\");\n}\n"
          % (cmd, "\n".join("    " + f for f in feed), sums))
    write(os.path.join(out, "src/events.rs"), events_rs(n))


def library_crate(out, n, library, version, mods, build_override):
    """A crate of machine modules `m<i>` (each with `run(events) -> u64`)
    over one state-machine library, its main summing their checksums."""
    write(os.path.join(out, "Cargo.toml"),
          "[package]\nname = \"machines-%s\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n"
          "[dependencies]\n%s = \"%s\"\n\n[workspace]\n%s" % (library, library, version, build_override))
    runs = "\n".join("    sum += m%d::run(EVENTS[%d]);" % (i, i) for i in range(n))
    write(os.path.join(out, "src/main.rs"),
          "mod events;\nuse events::EVENTS;\n%s\nfn main() {\n    let mut sum = 0u64;\n%s\n    println!(\"checksum {sum}\");\n}\n"
          % ("\n".join(mods), runs))
    write(os.path.join(out, "src/events.rs"), events_rs(n))


def smlang_crate(out, n, build_override):
    mods = []
    for i in range(n):
        trans = ",\n".join(
            "            %sS%d + E%d / add%d = S%d" % ("*" if k == 0 else "", f, ev, add, to)
            for k, (f, ev, to, add) in enumerate(TABLE))
        acts = "\n".join(
            "        fn add%d(&mut self) -> Result<(), ()> { self.count += %d; Ok(()) }" % (a, a)
            for a in sorted({t[3] for t in TABLE}))
        mods.append(
            "pub mod m%d {\n    use smlang::statemachine;\n    statemachine! {\n        transitions: {\n%s\n        }\n    }\n"
            "    pub struct Ctx { pub count: u32 }\n    impl StateMachineContext for Ctx {\n%s\n    }\n"
            "    pub fn run(events: &[u8]) -> u64 {\n        let mut sm = StateMachine::new(Ctx { count: 0 });\n"
            "        for e in events {\n            let ev = match e { 1 => Events::E1, 2 => Events::E2, _ => Events::E3 };\n"
            "            let _ = sm.process_event(ev);\n        }\n"
            "        let s = match sm.state() { States::S1 => 1, States::S2 => 2, States::S3 => 3, States::S4 => 4, States::S5 => 5 };\n"
            "        s * 1000 + u64::from(sm.context().count)\n    }\n}\n" % (i, trans, acts))
    library_crate(out, n, "smlang", "0.8", mods, build_override)


def statig_crate(out, n, build_override):
    mods = []
    for i in range(n):
        arms = []
        for s in range(1, STATES + 1):
            cases = "\n".join(
                "                %d => { self.count += %d; Transition(State::s%d()) }" % (ev, add, to)
                for (f, ev, to, add) in TABLE if f == s)
            arms.append(
                "        #[state]\n        fn s%d(&mut self, event: &u8) -> Outcome<State> {\n"
                "            match event {\n%s\n                _ => Handled,\n            }\n        }\n" % (s, cases))
        mods.append(
            "pub mod m%d {\n    use statig::prelude::*;\n    #[derive(Default)]\n    pub struct M { pub count: u32 }\n"
            "    #[state_machine(initial = \"State::s1()\")]\n    impl M {\n%s    }\n"
            "    pub fn run(events: &[u8]) -> u64 {\n        let mut sm = M::default().state_machine();\n"
            "        for e in events { sm.handle(e); }\n"
            "        let s = match sm.state() { State::S1 {} => 1, State::S2 {} => 2, State::S3 {} => 3, State::S4 {} => 4, State::S5 {} => 5 };\n"
            "        s * 1000 + u64::from(sm.count)\n    }\n}\n" % (i, "".join(arms)))
    library_crate(out, n, "statig", "0.4", mods, build_override)


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    out, n = args[0], int(args[1])
    rcsc = os.path.abspath(args[args.index("--rcsc") + 1]) if "--rcsc" in args else \
        os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    level = int(args[args.index("--build-opt") + 1]) if "--build-opt" in args else 1
    build_override = "" if level == 0 else BUILD_OVERRIDE % level
    rcsc_crate(os.path.join(out, "rcsc"), n, rcsc, build_override)
    smlang_crate(os.path.join(out, "smlang"), n, build_override)
    statig_crate(os.path.join(out, "statig"), n, build_override)
    print("expected checksum %d" % expected(n))


if __name__ == "__main__":
    main()
