//! With `Config::serde(SerdeDerives::Feature("serde"))` and the crate's
//! `serde` feature on, the generated buffer types and enums serialise
//! through serde, field by field and variant by variant, and read back
//! equal — so buffers can be logged, recorded and replayed.
#![cfg(feature = "serde")]

use rcs_plan_sets::set_0004_field_types::_0004_field_types::types as field_types;
use rcs_plan_sets::set_submarine::submarine::types;

#[test]
fn a_buffer_round_trips_through_json_with_its_field_names() {
    let ship = types::Ship {
        direction: types::ShipDirection::Backward,
        speed: 4.25,
    };
    let json = serde_json::to_string(&ship).unwrap();
    assert_eq!(json, r#"{"direction":"Backward","speed":4.25}"#);
    let back: types::Ship = serde_json::from_str(&json).unwrap();
    assert_eq!(back, ship);
    assert!(
        serde_json::from_str::<types::Ship>(r#"{"direction":"Sideways","speed":1.0}"#).is_err()
    );
}

#[test]
fn every_field_type_round_trips() {
    let mut value = field_types::Vehicle::default();
    value.s.e = i64::MIN;
    value.s.i = u64::MAX;
    value.s.j = 0.1;
    value.wheels[3].gear = field_types::Gear::High;
    value.grid[1][2] = 255;
    value.flags[0] = true;
    let json = serde_json::to_string(&value).unwrap();
    let back: field_types::Vehicle = serde_json::from_str(&json).unwrap();
    assert_eq!(back, value);
}
