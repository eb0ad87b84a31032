//! The loop both terminal apps run (`ronap view`, `ronap collect --human`): wait for a key or the
//! app's next tick, hand keys to the app, let it advance, redraw at most 60 times a second, and
//! stop on a signal (exit code 128 + signal) or when the app says so.

use super::terminal::{self, Session};
use anyhow::{Context, Result};
use ratatui::crossterm::event::{Event, KeyEvent};
use ratatui::Frame;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Shortest time between two redraws: at most 60 frames a second.
const FRAME: Duration = Duration::from_millis(16);

/// A screen the loop drives.
pub trait App {
    /// Draws the whole screen.
    fn draw(&self, frame: &mut Frame);

    /// How long the loop may wait for a key before [`App::tick`] is due.
    fn wait(&self) -> Duration;

    /// Handles a key; `Some(code)` ends the loop with that exit code.
    fn key(&mut self, key: &KeyEvent) -> Result<Option<ExitCode>>;

    /// Advances the app's own clock after each wait; `true` when the screen changed.
    fn tick(&mut self) -> Result<bool> {
        Ok(false)
    }
}

/// Runs `app` on `session` until it ends or a signal arrives.
pub fn run(session: &mut Session, app: &mut dyn App) -> Result<ExitCode> {
    let mut last_draw: Option<Instant> = None;
    let mut dirty = true;
    loop {
        if let Some(sig) = session.signal() {
            return Ok(ExitCode::from(u8::try_from(128 + sig).unwrap_or(130)));
        }
        let now = Instant::now();
        if dirty && last_draw.is_none_or(|t| now - t >= FRAME) {
            session
                .terminal()
                .draw(|f| app.draw(f))
                .context("cannot draw on the terminal")?;
            dirty = false;
            last_draw = Some(now);
        }
        let mut timeout = app.wait();
        if dirty {
            timeout = timeout.min(FRAME);
        }
        if let Some(event) = session.next_event(timeout)? {
            if matches!(event, Event::Resize(..)) {
                dirty = true;
            }
            if let Some(key) = terminal::key(&event) {
                dirty = true;
                if let Some(code) = app.key(&key)? {
                    return Ok(code);
                }
            }
        }
        dirty |= app.tick()?;
    }
}
