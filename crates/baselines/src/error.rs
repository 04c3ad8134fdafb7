//! The crate's one error type.

/// Everything that can go wrong in `baselines`: bad configurations and bad data. Nothing in
/// the crate panics on user input; every check returns one of these.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum BaselineError {
    /// A decoder, training or marching-cubes setting is out of range.
    #[error("invalid configuration: {field} = {value}: {reason}")]
    Config {
        /// The setting's name.
        field: &'static str,
        /// Its value.
        value: String,
        /// Why it is refused.
        reason: &'static str,
    },
    /// Training data or an input grid is malformed (lengths, non-finite values, missing targets).
    #[error("invalid data: {0}")]
    Data(String),
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, BaselineError>;

pub(crate) fn config_err<T>(field: &'static str, value: impl std::fmt::Display, reason: &'static str) -> Result<T> {
    Err(BaselineError::Config { field, value: value.to_string(), reason })
}
