// A numeric domain declared on a field that is not a number.
use cov_core::{Build, Checked, CovError, Operator, OperatorSpec, Spectrum};

#[derive(Debug)]
pub struct Label;

impl Operator for Label {
    fn apply(&self, _: &mut dyn Spectrum) -> Result<(), CovError> {
        Ok(())
    }
}

/// `Label(text: "a")`.
#[derive(OperatorSpec)]
#[operator(summary = "a label")]
pub struct LabelSpec {
    /// The text.
    #[param(positive)]
    pub text: String,
}

impl Build for LabelSpec {
    type Op = Label;
    fn make(_: Checked<Self>) -> Result<Label, CovError> {
        Ok(Label)
    }
}

fn main() {}
