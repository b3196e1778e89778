//! Why a scene could not be read: [`SceneError`], whose every message names the file.

/// Why a scene could not be read. Every message starts with the file (or the source name given
/// to `Scene::from_toml_str_named`).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read from disk.
    #[error("{file}: cannot read scene: {err}")]
    Io {
        /// The scene file as given.
        file: String,
        /// Underlying I/O error.
        err: std::io::Error,
    },
    /// Not valid TOML, an unknown key, a missing required key or a value of the wrong type.
    #[error("{file}: {}{msg}", line_prefix(.line))]
    Syntax {
        /// The scene file.
        file: String,
        /// 1-based line of the offending text, where the parser located it.
        line: Option<usize>,
        /// The parser's message (one line).
        msg: String,
    },
    /// A well-formed value that is out of range or inconsistent with another.
    #[error("{file}: {key}: {msg}")]
    Invalid {
        /// The scene file.
        file: String,
        /// The key, as `[table] key = value` (or `key = value` at the top level).
        key: String,
        /// What is wrong and what is expected.
        msg: String,
    },
}

/// `line 3: ` or empty.
fn line_prefix(line: &Option<usize>) -> String {
    match line {
        Some(line) => format!("line {line}: "),
        None => String::new(),
    }
}
