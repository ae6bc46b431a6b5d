//! Random small hierarchies (2–4 controllers) for the property tests of
//! the cross-controller analysis: supervisors that command subordinates,
//! wait on their answers (`X.done`, `X.error`, a status, a watchdog on
//! `X.stale_cycles`) or not, resend, time out and fail; subordinates that
//! end in `Error`, report, refuse (`accept when`); one or two CPUs of
//! different periods. Plain std (a splitmix64 generator), so that the
//! plan-sets build script includes this file too and compiles a
//! fixed-seed corpus of them for the generated-code backend.

/// A splitmix64 generator: the same seed gives the same hierarchy.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n` > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// True `percent` times in a hundred.
    pub fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
}

/// One generated plan set: its `.rcs` text and its manifest.
pub struct Hierarchy {
    pub plans: String,
    pub manifest: String,
}

/// What one controller declares, decided before any plan is written (a
/// supervisor's rows read its subordinates' declarations).
struct Shape {
    supervisor: Option<usize>,
    subordinates: Vec<usize>,
    status: bool,
    hook: bool,
    accept: Option<u64>,
    states: u64,
}

/// The hierarchy of `seed`.
pub fn random_hierarchy(seed: u64) -> Hierarchy {
    let mut rng = Rng::new(seed);
    let n = 2 + rng.below(3) as usize;
    let mut shapes: Vec<Shape> = Vec::with_capacity(n);
    for _ in 0..n {
        let states = 1 + rng.below(3);
        let status = rng.chance(40);
        let hook = rng.chance(30);
        let accept = rng.chance(15).then(|| 2 + rng.below(6));
        shapes.push(Shape {
            supervisor: None,
            subordinates: Vec::new(),
            status,
            hook,
            accept,
            states,
        });
    }
    for i in 1..n {
        let sup = rng.below(i as u64) as usize;
        shapes[i].supervisor = Some(sup);
        shapes[sup].subordinates.push(i);
    }
    let mut plans = String::from(
        "// A random hierarchy for the property tests.\nbuffer Sensor { a: bool, n: u8 }\n",
    );
    for (i, s) in shapes.iter().enumerate() {
        plans.push_str(&format!("controller C{i} {{\n    reads s{i}: Sensor\n"));
        if !s.subordinates.is_empty() {
            let subs: Vec<String> = s.subordinates.iter().map(|c| format!("C{c}")).collect();
            plans.push_str(&format!("    subordinates {}\n", subs.join(", ")));
        }
        match s.accept {
            Some(k) => plans.push_str(&format!("    command GO(m: u8) accept when cmd.m < {k}\n")),
            None => plans.push_str("    command GO(m: u8)\n"),
        }
        if s.status {
            plans.push_str("    status READY\n");
        }
        plans.push_str("    error FAIL\n");
        if s.hook {
            plans.push_str("    hook ok() -> bool\n");
        }
        plans.push_str("    plan GO {\n");
        for row in plan_rows(&mut rng, &shapes, i) {
            plans.push_str("        ");
            plans.push_str(&row);
            plans.push('\n');
        }
        plans.push_str("    }\n}\n");
    }
    // One CPU, or two of different periods with the controllers dealt out.
    let mut manifest = String::from("schedule:\n");
    if rng.chance(50) {
        let order: Vec<String> = (0..n).map(|i| format!("C{i}")).collect();
        manifest.push_str(&format!(
            "  - cpu: main\n    period: 10ms\n    order: [{}]\n",
            order.join(", ")
        ));
    } else {
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        for i in 0..n {
            if rng.chance(50) {
                fast.push(format!("C{i}"));
            } else {
                slow.push(format!("C{i}"));
            }
        }
        for (name, period, order) in [("fast", 10, fast), ("slow", 20, slow)] {
            if !order.is_empty() {
                manifest.push_str(&format!(
                    "  - cpu: {name}\n    period: {period}ms\n    order: [{}]\n",
                    order.join(", ")
                ));
            }
        }
    }
    Hierarchy { plans, manifest }
}

/// The rows of controller `i`'s plan `GO`.
fn plan_rows(rng: &mut Rng, shapes: &[Shape], i: usize) -> Vec<String> {
    let s = &shapes[i];
    let mut rows = Vec::new();
    let entry_jobs = jobs(rng, shapes, i, 60);
    rows.push(format!("*0 when new_command -> S1{entry_jobs}"));
    // A don't-care row that handles a subordinate's failure, sometimes.
    if let Some(&x) = s.subordinates.first() {
        if rng.chance(30) {
            rows.push(format!("*{} when C{x}.error -> Error(FAIL)", rows.len()));
        }
    }
    for state in 1..=s.states {
        let count = 1 + rng.below(3);
        for _ in 0..count {
            let cond = condition(rng, shapes, i);
            let target = match rng.below(6) {
                0 => "Done".to_string(),
                1 => "Error(FAIL)".to_string(),
                2 => "same".to_string(),
                _ => format!("S{}", 1 + rng.below(s.states)),
            };
            let jobs = jobs(rng, shapes, i, 35);
            rows.push(format!("S{state} when {cond} -> {target}{jobs}"));
        }
    }
    rows
}

/// A condition controller `i`'s rows can read.
fn condition(rng: &mut Rng, shapes: &[Shape], i: usize) -> String {
    let s = &shapes[i];
    let one = |rng: &mut Rng| -> String {
        let sub = (!s.subordinates.is_empty())
            .then(|| s.subordinates[rng.below(s.subordinates.len() as u64) as usize]);
        match (rng.below(11), sub) {
            (0, _) => format!("s{i}.a"),
            (1, _) => format!("!s{i}.a"),
            (2, _) => format!("s{i}.n > {}", rng.below(8)),
            (3, _) => format!("state_cycles > {}", 1 + rng.below(6)),
            (4, _) => format!("cmd.m > {}", rng.below(6)),
            (5, _) if s.hook => "ok()".into(),
            (6 | 5, Some(x)) => format!("C{x}.done"),
            (7, Some(x)) => format!("C{x}.error"),
            (8, Some(x)) if shapes[x].status => format!("C{x}.status == READY"),
            (8, Some(x)) => format!("C{x}.executing"),
            (9, Some(x)) => format!("C{x}.stale_cycles > {}", 1 + rng.below(5)),
            _ => format!("s{i}.a"),
        }
    };
    let first = one(rng);
    if rng.chance(30) {
        let second = one(rng);
        if second != first {
            return format!("{first} && {second}");
        }
    }
    first
}

/// A job list (with its leading space), `percent` of the time not empty:
/// a command to a subordinate, a report.
fn jobs(rng: &mut Rng, shapes: &[Shape], i: usize, percent: u64) -> String {
    let s = &shapes[i];
    let mut out = Vec::new();
    if !s.subordinates.is_empty() && rng.chance(percent) {
        let x = s.subordinates[rng.below(s.subordinates.len() as u64) as usize];
        let arg = if rng.chance(50) {
            format!("{}", rng.below(8))
        } else {
            "cmd.m".to_string()
        };
        out.push(format!("C{x} <- GO(m: {arg})"));
    }
    if s.status && rng.chance(percent / 2) {
        out.push("report READY".into());
    }
    if out.is_empty() {
        String::new()
    } else {
        format!(" {{ {} }}", out.join("; "))
    }
}
