//! The stability suite at its small size, through the library: the stable evaluator must
//! show no NaN, no infinity, no falloff, no value above the exact distance, no deviation
//! from the brute force and no render mismatch; the naive one must show its known
//! underflow (infinities far away), so the suite is seen to test something.

use smoothtrace::reports::NoProgress;
use smoothtrace::reports::stability::{self, Evaluator, Size};

#[test]
fn stable_evaluator_has_no_violation_and_naive_underflows() {
    let report = stability::run(Size::Small, &NoProgress);
    let bad = report.stable_violations();
    assert!(
        bad.is_empty(),
        "stable evaluator violations:\n{}",
        bad.join("\n")
    );
    let naive_inf: usize = report
        .results
        .iter()
        .filter(|r| r.evaluator == Evaluator::Naive)
        .map(|r| r.inf)
        .sum();
    assert!(
        naive_inf > 0,
        "the naive sum should underflow in the far cases"
    );
    for group in [
        "alpha",
        "distance",
        "scale",
        "degenerate",
        "max_alpha",
        "render",
    ] {
        assert!(
            report.results.iter().any(|r| r.group == group),
            "no case in group {group}"
        );
    }
    // Every render of a scaled copy was compared with the unscaled one and matched.
    let scaled: Vec<_> = report
        .results
        .iter()
        .filter(|r| r.case.contains("tiny") || r.case.contains("huge"))
        .collect();
    assert_eq!(scaled.len(), 4);
    for r in scaled {
        let c = r.render.as_ref().unwrap();
        assert_eq!(c.matches, Some(true), "{}: {c:?}", r.case);
    }
}
