//! Helpers shared by the integration tests (each test file that needs them says `mod common;`).
#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs `cmd`, asserts that it succeeded (showing its standard error when not) and returns
/// its output.
pub fn succeed(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The railforce binary under test, started in `dir`.
pub fn railforce_in(dir: &std::path::Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_railforce"));
    c.current_dir(dir);
    c
}

/// Whether `python3` imports `modules` (e.g. `"numpy, pyarrow"`). Where it does not, the
/// check is skipped with a message — unless RAILFORCE_PYTHON_TESTS is set (CI), which makes
/// the Python checks mandatory.
pub fn python_with(modules: &str) -> bool {
    let ok = Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os("RAILFORCE_PYTHON_TESTS").is_none(),
            "python3 with {modules} is required (RAILFORCE_PYTHON_TESTS is set)"
        );
        eprintln!("skipping the Python check: no python3 with {modules}");
    }
    ok
}
