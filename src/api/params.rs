//! Parameter checks shared by the command line and the Python bindings, with the same
//! messages in both; only the way a parameter is named differs ([`Naming`]).

use super::InputError;
use crate::eval::params::MAX_PRUNE_TOLERANCE;
use crate::scene::{AlphaSpec, MAX_IMAGE_SIZE, Scene};

/// Largest accepted worker-thread count.
pub const MAX_THREADS: i64 = 1024;

/// How a front end names a parameter in messages: the command line's flags
/// (`--alpha-rel`) or Python's keyword arguments (`alpha_rel`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    Flag,
    Keyword,
}

impl Naming {
    /// The name of parameter `key` (written in snake case).
    pub fn name(self, key: &str) -> String {
        match self {
            Naming::Flag => format!("--{}", key.replace('_', "-")),
            Naming::Keyword => key.to_string(),
        }
    }
}

fn bad(message: String) -> InputError {
    InputError::Parameter(message)
}

/// Alpha (or max_alpha: `key`) from an absolute value or one relative to the bounding-box
/// diagonal `diag` (`alpha = rel / diag`); the absolute value wins when both are given.
/// `None` when neither is given.
pub fn resolve_alpha(
    naming: Naming,
    key: &str,
    abs: Option<f64>,
    rel: Option<f64>,
    diag: f64,
) -> Result<Option<f64>, InputError> {
    let (name, rel_name) = (naming.name(key), naming.name(&format!("{key}_rel")));
    let v = match (abs, rel) {
        (Some(a), _) => a,
        (None, Some(r)) => {
            if !(r > 0.0 && r.is_finite()) {
                return Err(bad(format!(
                    "{rel_name} must be a positive number (got {r})"
                )));
            }
            if diag.is_nan() || diag <= 0.0 {
                return Err(bad(format!(
                    "{rel_name} needs a mesh with a non-zero bounding box (this one's \
                     diagonal is {diag}: a single point or coincident vertices); give {name}"
                )));
            }
            let v = r / diag;
            if let Some(problem) = crate::limits::alpha_problem(v) {
                return Err(bad(format!(
                    "{rel_name} {r} over the diagonal {diag} gives alpha {v}, which {problem}"
                )));
            }
            v
        }
        (None, None) => return Ok(None),
    };
    if let Some(problem) = crate::limits::alpha_problem(v) {
        return Err(bad(format!("{name} {problem}")));
    }
    Ok(Some(v))
}

/// Beta must be in [0, 1].
pub fn check_beta(naming: Naming, beta: f64) -> Result<f64, InputError> {
    if !(0.0..=1.0).contains(&beta) {
        return Err(bad(format!(
            "{} must be in [0, 1] (got {beta})",
            naming.name("beta")
        )));
    }
    Ok(beta)
}

/// The pruning of queries from `tolerance`, how far it may lower the smooth distance at
/// most (a length, in the mesh's units; `eval::smooth`: subtrees holding together a share
/// `tol` of the sum lower it by at most `2 tol / alpha`, `EvalParams::pruning_bound`):
/// `tol = alpha tolerance / 2`, at most [`MAX_PRUNE_TOLERANCE`] (as the tracer's); 0
/// turns pruning off (the Barnes-Hut sum itself). `None` keeps the default share
/// ([`crate::eval::params::PRUNE_TOLERANCE`]).
pub fn apply_tolerance(
    naming: Naming,
    tolerance: Option<f64>,
    params: &mut crate::eval::EvalParams,
) -> Result<(), InputError> {
    let Some(t) = tolerance else {
        return Ok(());
    };
    if !(t >= 0.0 && t.is_finite()) {
        return Err(bad(format!(
            "{} must be a length >= 0 (got {t})",
            naming.name("tolerance")
        )));
    }
    if t == 0.0 {
        params.prune = false;
    } else {
        params.prune_tolerance = (0.5 * params.alpha * t).min(MAX_PRUNE_TOLERANCE);
    }
    Ok(())
}

/// A worker-thread count in `0..=MAX_THREADS` (0 = all cores).
pub fn check_threads(name: &str, threads: i64) -> Result<usize, InputError> {
    if !(0..=MAX_THREADS).contains(&threads) {
        return Err(bad(format!(
            "{name} must be in 0..={MAX_THREADS} (got {threads})"
        )));
    }
    Ok(threads as usize)
}

/// An image width or height in `1..=MAX_IMAGE_SIZE`.
pub fn check_image_size(name: &str, v: i64) -> Result<u32, InputError> {
    if !(1..=i64::from(MAX_IMAGE_SIZE)).contains(&v) {
        return Err(bad(format!(
            "{name} must be in 1..={MAX_IMAGE_SIZE} (got {v})"
        )));
    }
    Ok(v as u32)
}

/// Values that replace a loaded scene's own (`smoothtrace render --width ...`,
/// `smoothtrace.render(path, width=...)`).
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneOverrides {
    pub width: Option<i64>,
    pub height: Option<i64>,
    pub beta: Option<f64>,
    /// Replaces every object's alpha.
    pub alpha: Option<AlphaSpec>,
    pub threads: Option<i64>,
}

impl SceneOverrides {
    /// Checks and applies the overrides; the caller validates the scene again after.
    pub fn apply(&self, scene: &mut Scene, naming: Naming) -> Result<(), InputError> {
        if let Some(w) = self.width {
            scene.image.width = check_image_size(&naming.name("width"), w)?;
        }
        if let Some(h) = self.height {
            scene.image.height = check_image_size(&naming.name("height"), h)?;
        }
        if let Some(b) = self.beta {
            scene.render.beta = check_beta(naming, b)?;
        }
        if let Some(a) = self.alpha {
            if !(a.value() > 0.0 && a.value().is_finite()) {
                return Err(bad(format!(
                    "{} must be a positive number (got {})",
                    naming.name(a.key()),
                    a.value()
                )));
            }
            for o in &mut scene.objects {
                o.alpha = a;
            }
        }
        if let Some(t) = self.threads {
            scene.render.threads = check_threads(&naming.name("threads"), t)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_use_the_front_end_names() {
        let e = resolve_alpha(Naming::Flag, "max_alpha", None, Some(-1.0), 1.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--max-alpha-rel must be a positive number (got -1)"
        );
        let e = resolve_alpha(Naming::Keyword, "alpha", None, Some(2.0), 0.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "alpha_rel needs a mesh with a non-zero bounding box (this one's diagonal is 0: \
             a single point or coincident vertices); give alpha"
        );
        assert_eq!(
            resolve_alpha(Naming::Keyword, "alpha", None, Some(3.0), 2.0).unwrap(),
            Some(1.5)
        );
        let e = check_beta(Naming::Keyword, 1.5).unwrap_err();
        assert_eq!(e.to_string(), "beta must be in [0, 1] (got 1.5)");
    }
}
