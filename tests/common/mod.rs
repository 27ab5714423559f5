//! Helpers shared by the integration tests that drive the `whitted` binary.
#![allow(dead_code)] // each test file uses some of them

use std::process::{Command, Output};

#[cfg(all(feature = "cli", feature = "viewer"))]
pub mod x11;

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

/// Gives up on `test` because of `why`, so that nobody takes it for a pass: under
/// `CI=true` (CI installs every tool and runs as root) it fails; elsewhere it says
/// `SKIPPED … NOT tested` on the harness's own stderr (the harness keeps a passing
/// test's `eprintln!` output to itself).
pub fn skip(test: &str, why: &str, subject: &str) {
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{test}: {why}; CI=true, so {subject} must be tested");
    }
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED {test}: {why}: {subject} was NOT tested"
    );
}

/// The names in `dir`, sorted.
pub fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
