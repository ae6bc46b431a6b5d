//! Run N cycles of one servo-loop variant, for instruction counting:
//! `valgrind --tool=callgrind target/release/examples/servo_count generated 100000`.

use rcs_plan_sets::servo;

fn main() {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "generated".to_string());
    let n: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(100_000);
    match which.as_str() {
        "generated" => {
            let mut l = servo::generated().expect("setup");
            for _ in 0..n {
                l.step();
            }
            println!("{:?}", l.observe());
        }
        "hand" => {
            let mut l = servo::hand_written().expect("setup");
            for _ in 0..n {
                l.step();
            }
            println!("{:?}", l.observe());
        }
        _ => {
            let mut l = servo::CLoop::new().expect("free");
            for _ in 0..n {
                l.step();
            }
            println!("{:?}", l.observe());
        }
    }
}
