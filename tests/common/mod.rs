//! Helpers shared by the integration tests that drive the `whitted` binary.

use std::process::Command;

/// Runs `whitted` with `args`, asserts that it succeeded, and returns its stdout.
pub fn whitted(args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(args)
        .output()
        .expect("run whitted");
    assert!(
        out.status.success(),
        "whitted {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}
