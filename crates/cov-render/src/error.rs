//! The renderer's errors: one type, each variant one line that says what was wrong and
//! where.

/// An error in a scene file, in one line: `file:line:col: message`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{}{message}", at.map(|(l, c)| format!("{l}:{c}: ")).unwrap_or_else(|| " ".into()))]
pub struct SceneError {
    /// The scene file.
    pub file: String,
    /// Line and column, when known.
    pub at: Option<(usize, usize)>,
    /// What is wrong.
    pub message: String,
}

/// What can go wrong when rendering, in one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// The scene file (positioned: `file:line:col: message`).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An operator of the covariance pass rejected what the scene gave it.
    #[error("covariance path at pixel ({x}, {y}): {message}")]
    Covariance {
        /// Pixel column.
        x: u32,
        /// Pixel row.
        y: u32,
        /// The operator's error.
        message: String,
    },
    /// The covariance pass could not set up the camera's operators.
    #[error("covariance camera: {0}")]
    Camera(String),
    /// A setting out of range, named as the caller wrote it.
    #[error("{name} must be {expected}, got {got}")]
    Setting {
        /// The setting (`--spp`, `cov_stride`, …).
        name: &'static str,
        /// What it must be.
        expected: String,
        /// What it was.
        got: String,
    },
    /// Two images (or an image and its maps) of different sizes.
    #[error("{what}: {a_w}x{a_h} against {b_w}x{b_h}")]
    Size {
        /// What was compared.
        what: &'static str,
        /// First width.
        a_w: u32,
        /// First height.
        a_h: u32,
        /// Second width.
        b_w: u32,
        /// Second height.
        b_h: u32,
    },
    /// Parts of a render that do not make one render (`parts::merge`).
    #[error("{0}")]
    Parts(String),
    /// The denoiser is not in this build, or failed.
    #[error("{0}")]
    Denoiser(String),
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    File {
        /// The file, as given.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl RenderError {
    /// A file error for `path`.
    pub fn file(path: &std::path::Path, e: impl std::fmt::Display) -> RenderError {
        RenderError::File {
            path: cov_core::one_line(&path.display().to_string()),
            message: cov_core::one_line(&e.to_string()),
        }
    }

    /// A setting error.
    pub fn setting(
        name: &'static str,
        expected: impl Into<String>,
        got: impl std::fmt::Display,
    ) -> RenderError {
        RenderError::Setting {
            name,
            expected: expected.into(),
            got: crate::echo(&got.to_string()),
        }
    }
}

/// `Ok` if `path` is a regular file (or a link to one); otherwise what it is instead, in
/// one line: missing, there but not a file (a directory, a device such as `/dev/zero`), or
/// unreadable for another reason (a loop of links, a folder without permission).
pub(crate) fn regular_file(path: &std::path::Path) -> Result<(), String> {
    let shown = || cov_core::one_line(&path.display().to_string());
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(()),
        Ok(_) => Err(format!("not a regular file: {}", shown())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(format!("no such file: {}", shown())),
        // A link loop, a directory on the way that cannot be searched: the system's reason.
        Err(e) => Err(format!("{}: {}", shown(), cov_core::one_line(&e.to_string()))),
    }
}

/// `Ok` if the file at `path`, a `what` file (scene, OBJ, texture), is at most `limit`
/// bytes long by its length; otherwise one line saying so. A device or a pipe reports no
/// length: a reader that reads it must stop past `limit` itself (as `read_bounded` in world.rs does).
pub(crate) fn within_length(path: &std::path::Path, limit: u64, what: &str) -> Result<(), String> {
    let len = std::fs::metadata(path)
        .map_err(|e| cov_core::one_line(&e.to_string()))?
        .len();
    if len > limit {
        return Err(format!(
            "the file is {len} bytes; {what} files are read up to {limit} bytes"
        ));
    }
    Ok(())
}
