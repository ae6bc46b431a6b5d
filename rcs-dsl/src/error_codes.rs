//! A controller's error codes by name and back: the runtime's built-ins
//! (`UNKNOWN_COMMAND`, `INDEX_RANGE`, `HOOK_PANIC`, `REFUSED`), which every
//! controller can end with or answer, and the codes it declares. One table
//! for scenarios, the interpreter's reports and the type checker, so that
//! a name means the same number everywhere (`rcs_runtime::ErrorCode`).

use crate::ir::Controller;
use rcs_runtime::ErrorCode;

/// The built-in error codes, by the name plans and scenarios write.
pub const BUILTIN: [(&str, ErrorCode); 4] = [
    ("UNKNOWN_COMMAND", ErrorCode::UNKNOWN_COMMAND),
    ("INDEX_RANGE", ErrorCode::INDEX_RANGE),
    ("HOOK_PANIC", ErrorCode::HOOK_PANIC),
    ("REFUSED", ErrorCode::REFUSED),
];

/// Whether `name` is a built-in error code.
pub fn is_builtin(name: &str) -> bool {
    BUILTIN.iter().any(|(n, _)| *n == name)
}

/// The code of error `name` of controller `c`: a built-in or one it declares.
pub fn code_of(c: &Controller, name: &str) -> Option<ErrorCode> {
    BUILTIN
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, code)| *code)
        .or_else(|| {
            c.errors
                .iter()
                .position(|e| e.name == name)
                .map(|i| ErrorCode::custom(i as u16))
        })
}

/// The name of `code` in controller `c` (`none` for no error; the number
/// for a code it does not have).
pub fn name_of(c: &Controller, code: ErrorCode) -> String {
    if code.is_none() {
        return "none".to_string();
    }
    if let Some((n, _)) = BUILTIN.iter().find(|(_, k)| *k == code) {
        return (*n).to_string();
    }
    usize::from(code.0)
        .checked_sub(usize::from(ErrorCode::FIRST_CUSTOM))
        .and_then(|i| c.errors.get(i))
        .map_or_else(|| code.0.to_string(), |e| e.name.clone())
}
