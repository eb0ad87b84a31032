//! The terminal front of the interactive commands: a [`terminal::Session`] that takes the
//! terminal and always gives it back, and [`draw`], which turns an episode into a ratatui frame.
//! Drawing is a pure function of the state it is given, so tests render it into a
//! `TestBackend`; only the session touches the real terminal.

pub mod draw;
pub mod terminal;
