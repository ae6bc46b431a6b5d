//! The generated propulsion controller, the hand-written one and the C port
//! of the methodology's template run Appendix C's servo loop identically,
//! cycle by cycle: same state, same status, same RPM sent to the turbine,
//! same status fields (RPM ordered, ship speed) published every cycle.

use rcs_plan_sets::servo;

#[test]
fn generated_hand_written_and_c_agree_on_the_servo_loop() {
    let mut generated = servo::generated().expect("setup");
    let mut hand = servo::hand_written().expect("setup");
    let mut c = servo::CLoop::new().expect("the C port is free");
    let mut seen_statuses = Vec::new();
    for cycle in 0..60 {
        generated.step();
        hand.step();
        c.step();
        let g = generated.observe();
        assert_eq!(
            g,
            hand.observe(),
            "generated vs hand-written at cycle {cycle}"
        );
        assert_eq!(g, c.observe(), "generated vs C at cycle {cycle}");
        seen_statuses.push(g.1);
    }
    // The loop really runs: in S1, reporting AT_GOAL (custom status 4) on
    // the at-speed turns, and moving the RPM below and above the goal's.
    assert_eq!(generated.observe().0, 1, "in S1");
    assert!(
        seen_statuses.contains(&4),
        "AT_GOAL reported: {seen_statuses:?}"
    );
    let first_rpm = servo::GOAL * 10.0;
    assert_ne!(generated.observe().2, 0.0);
    // The status fields are published: the RPM ordered is the RPM sent,
    // and the ship speed is one the world wrote.
    let (ordered, speed) = generated.observe().3;
    assert_eq!(ordered, generated.observe().2, "ordered_rpm follows rpm");
    assert!(servo::SHIP_SPEEDS.contains(&speed), "ship_speed {speed}");
    assert!(
        (generated.observe().2 - first_rpm).abs() <= 2.0,
        "RPM stays near the model's {first_rpm}"
    );
}
