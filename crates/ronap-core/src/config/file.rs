//! Configuration and scenario files: reading one within the size bound, and errors that name the
//! file, the line and the key.

use crate::config::{ConfigError, SimConfig};

/// A configuration or scenario file as read: its path and text, for naming lines in errors.
#[derive(Clone, Debug)]
pub struct ConfigFile {
    path: std::path::PathBuf,
    text: String,
}

impl ConfigFile {
    /// Reads `path` (not yet parsed).
    pub fn read(path: &std::path::Path) -> Result<Self, ConfigError> {
        let text =
            crate::bounded::read_to_string(path, crate::bounded::TEXT_LIMIT).map_err(|e| {
                ConfigError::File {
                    path: path.to_path_buf(),
                    line: None,
                    message: format!("cannot read: {e}"),
                }
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            text,
        })
    }

    /// A file of `text` said to be at `path` (for text that did not come from disk).
    pub fn from_text(path: &std::path::Path, text: String) -> Self {
        Self {
            path: path.to_path_buf(),
            text,
        }
    }

    /// The file.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// `path:line` of the `[[moving]]` or `[[crowd]]` field an error `message` names (a part of
    /// it reading `crowd[0].pattern_radius_px = 8000: ...`), when this file sets it: how an error
    /// found only once the scene is built (a crowd pattern that leaves it) names the file and
    /// line, as a bad value does when the file is read.
    pub fn line_of(&self, message: &str) -> Option<String> {
        let key = message
            .split(": ")
            .find(|part| part.starts_with("moving[") || part.starts_with("crowd["))?
            .split(" = ")
            .next()?;
        key_line(&self.text, key).map(|line| format!("{}:{line}", self.path.display()))
    }

    /// The file's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The configuration the file sets (unset fields keep their defaults), with a map scene's
    /// file made relative to the directory of this file. An unknown key or a wrong type is an
    /// error naming the file, line, key and value.
    pub fn parse(&self) -> Result<SimConfig, ConfigError> {
        let mut config: SimConfig = toml::from_str(&self.text).map_err(|e| {
            let message = e.message().trim().replace('\n', " ");
            let line = e.span().map(|span| {
                self.text[..span.start.min(self.text.len())]
                    .matches('\n')
                    .count()
                    + 1
            });
            let quoted = line
                .and_then(|l| self.text.lines().nth(l - 1))
                .map(|t| format!("`{}`: ", t.trim()))
                .unwrap_or_default();
            ConfigError::File {
                path: self.path.clone(),
                line,
                message: format!("{quoted}{message}"),
            }
        })?;
        if let Some(file) = &mut config.scene.file {
            if file.is_relative() {
                if let Some(dir) = self.path.parent() {
                    *file = dir.join(&*file);
                }
            }
        }
        Ok(config)
    }

    /// `error` from validating a configuration read from this file, with the file and the line
    /// of the offending key when the file sets it (a value from a flag has no line here).
    pub fn locate(&self, error: ConfigError) -> ConfigError {
        let ConfigError::OutOfRange { field, .. } = &error else {
            return error;
        };
        match key_line(&self.text, field) {
            Some(line) => ConfigError::File {
                path: self.path.clone(),
                line: Some(line),
                message: error.to_string(),
            },
            None => error,
        }
    }
}

/// The line (from 1) where `field` (`laser.beams`, `moving[2].speed_px`, `scene.file`) is set in
/// TOML `text` written with `[section]` / `[[array]]` headers, if it is.
pub fn key_line(text: &str, field: &str) -> Option<usize> {
    let (table, key) = field.split_once('.').unwrap_or((field, ""));
    let (name, index) = match table.split_once('[') {
        Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
        None => (table, None),
    };
    let mut current = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    let mut current_index = None;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if let Some(h) = line.strip_prefix("[[").and_then(|l| l.strip_suffix("]]")) {
            let h = h.trim().to_string();
            let n = counts.entry(h.clone()).or_insert(0);
            current_index = Some(*n);
            *n += 1;
            if key.is_empty() && h == name && (index.is_none() || index == current_index) {
                return Some(i + 1);
            }
            current = h;
            continue;
        }
        if let Some(h) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            current = h.trim().to_string();
            current_index = None;
            continue;
        }
        let Some((k, _)) = line.split_once('=') else {
            continue;
        };
        let k = k.trim();
        let here = current == name && (index.is_none() || index == current_index);
        // The key itself, or an inline table holding it: `orca = { max_neighbours = 5 }`.
        if here && (k == key || key.strip_prefix(k).is_some_and(|r| r.starts_with('.'))) {
            return Some(i + 1);
        }
        // A dotted key at the top level: `laser.beams = 9`.
        if current.is_empty() && index.is_none() && k == field {
            return Some(i + 1);
        }
    }
    None
}
