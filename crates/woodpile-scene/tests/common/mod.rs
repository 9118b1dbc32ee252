//! What the scene crate's tests share.
#![allow(dead_code, clippy::unwrap_used)]

use std::path::Path;

use woodpile_scene::{parse, SceneError};

/// The key a scene file `text` is refused for (it must be refused for an invalid key).
pub fn invalid_key(text: &str) -> String {
    match parse(text, Path::new("s.toml")) {
        Err(SceneError::Invalid { key, .. }) => key,
        other => panic!("expected an invalid key for {text:?}, got {other:?}"),
    }
}
