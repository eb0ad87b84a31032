//! The terminal front of the interactive commands: a [`terminal::Session`] that takes the
//! terminal and always gives it back, [`draw`], which turns an episode into a ratatui frame, the
//! [`app`] loop both screens run, and the two screens: [`view`] (`ronap view`) and [`collect`]
//! (`ronap collect --human`). Drawing is a pure function of the state it is given, so tests
//! render it into a `TestBackend`; only the session touches the real terminal.

pub mod app;
pub mod collect;
pub mod draw;
pub mod team_view;
pub mod terminal;
pub mod view;
