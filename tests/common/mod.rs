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

/// An empty scratch folder `railforce-TAG-PID` under the system's temporary directory.
pub fn scratch(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("railforce-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
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

/// The C80's file with `edit` applied, loaded from a temporary folder: the error, or "loaded".
pub fn load_c80_edited(edit: impl Fn(String) -> String) -> String {
    let text = std::fs::read_to_string(
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("vehicles/c80.toml"),
    )
    .unwrap();
    let urdf = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("vehicles/c80.urdf");
    let text = edit(text).replace(
        "urdf = \"c80.urdf\"",
        &format!("urdf = {:?}", urdf.to_string_lossy()),
    );
    let dir = std::env::temp_dir().join(format!("railforce-edited-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!(
        "c80-{}.toml",
        railforce::io::fnv1a64(text.as_bytes())
    ));
    std::fs::write(&path, text).unwrap();
    let r = railforce::vehicle::Vehicle::load(&path);
    let _ = std::fs::remove_file(&path);
    match r {
        Ok(_) => "loaded".into(),
        Err(e) => e.to_string(),
    }
}

/// A tiny data set (the C80 on tangent track at 60 km/h, 0.4 s, seeds 1–3) and a tree
/// model trained on it, made with the binary in `dir`: `(plan, data, model)`.
pub fn tiny_data_and_tree_model(
    dir: &std::path::Path,
) -> (std::path::PathBuf, std::path::PathBuf, std::path::PathBuf) {
    let root = env!("CARGO_MANIFEST_DIR");
    let plan = dir.join("p.plan.toml");
    std::fs::write(
        &plan,
        format!(
            "name = \"p\"\nvehicle = \"{root}/vehicles/c80.toml\"\nduration_s = 0.4\nseeds = [1, 2, 3]\n\
             [[condition]]\nname = \"tangent\"\ntrack = \"{root}/tracks/tangent.toml\"\nspeed_kmh = 60.0\n"
        ),
    )
    .unwrap();
    let (data, model) = (dir.join("data"), dir.join("model"));
    let run = |args: &[&str]| {
        succeed(Command::new(env!("CARGO_BIN_EXE_railforce")).args(args));
    };
    run(&[
        "generate",
        "--plan",
        plan.to_str().unwrap(),
        "--out",
        data.to_str().unwrap(),
        "--settle",
        "0.1",
    ]);
    run(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "tree",
        "--out",
        model.to_str().unwrap(),
    ]);
    (plan, data, model)
}
