//! The speed matrix's guard (issue 30): every cell of `smoothtrace bench --matrix` at
//! 96x54 (8 meshes of `data/` x points, edges, triangles x alpha * diagonal 100 to 10000
//! x far and close views) is rendered and its counts (leaves per ray, full evaluations
//! and bound steps per hit ray: deterministic, whatever the machine or thread count)
//! compared with the committed baseline `tests/baselines/speed_matrix_96x54.json`. A cell
//! whose count rises by more than 3% fails. A change that trades cells rewrites the
//! baseline in the same commit (the command is in the failure message) and says why.
//! Skips, saying why, when the shared meshes are not linked as `data/`.

mod common;

use std::path::PathBuf;
use std::process::Command;

#[test]
fn every_cell_of_the_speed_matrix_stays_within_its_baseline() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let data = root.join("data");
    // Every mesh of the matrix must be there; otherwise this is not the shared data.
    for (_, file) in smoothtrace::reports::matrix::MESHES {
        if common::data_file(file).is_none() {
            return;
        }
    }
    let baseline = root.join("tests/baselines/speed_matrix_96x54.json");
    let out = Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
        .current_dir(&root)
        .args([
            "bench",
            "--matrix",
            "--width",
            "96",
            "--height",
            "54",
            "--threads",
            "2",
        ])
        .arg("--data-dir")
        .arg(&data)
        .arg("--check")
        .arg(&baseline)
        .output()
        .expect("run smoothtrace");
    let stderr = String::from_utf8_lossy(&out.stderr);
    let regressions: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("regression:"))
        .collect();
    assert!(
        out.status.success(),
        "the speed matrix rose against its baseline:\n{}\n(if a change trades cells on purpose, rewrite the baseline with \
         `smoothtrace bench --matrix --width 96 --height 54 --write-baseline tests/baselines/speed_matrix_96x54.json` \
         and say why in the commit)\n--- stderr\n{stderr}",
        regressions.join("\n")
    );
    let last = stderr.lines().last().unwrap_or("");
    // All cells compared: 7 meshes x 3 kinds + the deer's points, x 5 alphas x 2 views.
    assert!(
        last.starts_with("220 cells within"),
        "expected all 220 cells compared, got: {last}"
    );
}
