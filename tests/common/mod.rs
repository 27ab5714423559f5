//! Helpers shared by the integration tests that drive the `whitted` binary.
#![allow(dead_code)] // each test file uses some of them

use std::process::{Command, Output};

/// Runs `whitted` with `args` and returns what it did.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .args(args)
        .output()
        .expect("run whitted")
}

/// Runs `whitted` with `args`, asserts that it succeeded, and returns its stdout.
pub fn whitted(args: &[&str]) -> Vec<u8> {
    let out = run(args);
    assert!(
        out.status.success(),
        "whitted {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}
