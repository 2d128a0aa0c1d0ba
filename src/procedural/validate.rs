//! Parameter checks for [`super::Generator::build`]: each failure names the generator,
//! the parameter, the value given and what is expected.

use super::GeneratorError;

/// Upper bound on the primitives (triangles + segments, or points) one generator may
/// produce: beyond this a typo (an extra zero) would exhaust memory instead of failing.
pub const MAX_PRIMITIVES: u128 = 50_000_000;

/// Checks the parameters of one generator.
pub struct Check {
    generator: &'static str,
}

impl Check {
    pub fn new(generator: &'static str) -> Check {
        Check { generator }
    }

    fn fail(&self, message: String) -> GeneratorError {
        GeneratorError {
            generator: self.generator,
            message,
        }
    }

    /// `value` is finite and > 0.
    pub fn positive(&self, name: &str, value: f32) -> Result<(), GeneratorError> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(self.fail(format!(
                "`{name}` = {value}: expected a finite number greater than 0"
            )))
        }
    }

    /// `value` is finite (any sign).
    pub fn finite(&self, name: &str, value: f32) -> Result<(), GeneratorError> {
        if value.is_finite() {
            Ok(())
        } else {
            Err(self.fail(format!("`{name}` = {value}: expected a finite number")))
        }
    }

    /// `value < bound`, where `bound` is another parameter.
    pub fn smaller(
        &self,
        name: &str,
        value: f32,
        bound_name: &str,
        bound: f32,
    ) -> Result<(), GeneratorError> {
        if value < bound {
            Ok(())
        } else {
            Err(self.fail(format!(
                "`{name}` = {value}: expected less than `{bound_name}` = {bound}"
            )))
        }
    }

    /// `value >= min`.
    pub fn at_least(&self, name: &str, value: usize, min: usize) -> Result<(), GeneratorError> {
        if value >= min {
            Ok(())
        } else {
            Err(self.fail(format!("`{name}` = {value}: expected at least {min}")))
        }
    }

    /// `count` primitives (computed by the caller in `u128`, so it cannot overflow) are
    /// within [`MAX_PRIMITIVES`]; `what` shows how the parameters make the count.
    pub fn primitives(&self, count: u128, what: &str) -> Result<(), GeneratorError> {
        if count <= MAX_PRIMITIVES {
            Ok(())
        } else {
            Err(self.fail(format!(
                "{what} = {count} primitives, more than the limit of {MAX_PRIMITIVES}; \
                 lower the counts"
            )))
        }
    }
}
