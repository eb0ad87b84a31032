//! Owning the terminal: raw mode, the alternate screen and a hidden cursor while a session lives,
//! and the terminal as it was afterwards, whichever way the session ends: return, error, panic
//! (a panic hook restores it before the message prints), Ctrl-C (a key event in raw mode, left to
//! the caller) or SIGINT/SIGTERM/SIGHUP (a flag the caller polls).
//!
//! A loop that stops polling cannot see the flag: a Python policy that blocks, or crossterm
//! itself, whose reader spins on a terminal that hung up (a closed SSH connection or tmux pane
//! reads end-of-file forever). So a watchdog thread gives the caller [`GRACE`] to end after a
//! signal, then restores the terminal and exits with 128 + the signal. A second signal changes
//! nothing (signals come in pairs: `timeout` signals the process and its group), so the session
//! always ends by the loop or by the watchdog, with the terminal restored.

use anyhow::{bail, Context, Result};
use ratatui::backend::CrosstermBackend;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use ratatui::crossterm::{cursor, execute, terminal};
use ratatui::Terminal;
use std::io::{IsTerminal, Stdout};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Once};
use std::time::{Duration, Instant};

/// How long the loop has to end by itself after a signal before the watchdog ends the process.
pub const GRACE: Duration = Duration::from_secs(1);

/// The terminal while a command draws on it.
pub struct Session {
    terminal: Terminal<CrosstermBackend<Stdout>>,
    signal: Arc<AtomicUsize>,
    ended: Arc<AtomicBool>,
    #[cfg(unix)]
    handlers: Vec<signal_hook::SigId>,
}

/// Checks that stdout is a terminal: an interactive command cannot draw into a pipe or a file.
pub fn require_terminal(command: &str) -> Result<()> {
    if !std::io::stdout().is_terminal() {
        bail!(
            "ronap {command} draws in a terminal, and stdout is not one (run it in a terminal; \
             `ronap replay` and `ronap run --gif` write episodes as GIF files instead)"
        );
    }
    Ok(())
}

/// Gives the terminal back: raw mode off, main screen, cursor shown. Safe to call more than once.
pub fn restore() {
    let _ = terminal::disable_raw_mode();
    let _ = execute!(
        std::io::stdout(),
        terminal::LeaveAlternateScreen,
        cursor::Show
    );
}

/// Makes every panic restore the terminal before its message is printed, so the message is
/// readable and the shell usable.
fn install_panic_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            restore();
            previous(info);
        }));
    });
}

impl Session {
    /// Takes the terminal for `command` (`view`, `collect`). Fails, with the terminal untouched,
    /// when stdout is not a terminal.
    pub fn start(command: &str) -> Result<Self> {
        require_terminal(command)?;
        install_panic_hook();
        let signal = Arc::new(AtomicUsize::new(0));
        #[cfg(unix)]
        let handlers = {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let mut ids = Vec::new();
            let context = "cannot install signal handlers";
            for sig in [SIGINT, SIGTERM, SIGHUP] {
                ids.push(
                    signal_hook::flag::register_usize(sig, signal.clone(), sig as usize)
                        .context(context)?,
                );
            }
            ids
        };
        let ended = Arc::new(AtomicBool::new(false));
        watchdog(signal.clone(), ended.clone());
        let backend = CrosstermBackend::new(std::io::stdout());
        // The session exists before the terminal changes, so every early return restores it.
        let mut session = Self {
            terminal: Terminal::new(backend).context("cannot use the terminal")?,
            signal,
            ended,
            #[cfg(unix)]
            handlers,
        };
        terminal::enable_raw_mode().context("cannot switch the terminal to raw mode")?;
        execute!(
            std::io::stdout(),
            terminal::EnterAlternateScreen,
            cursor::Hide
        )
        .context("cannot switch to the alternate screen")?;
        session
            .terminal
            .clear()
            .context("cannot clear the terminal")?;
        Ok(session)
    }

    /// The terminal to draw on.
    pub fn terminal(&mut self) -> &mut Terminal<CrosstermBackend<Stdout>> {
        &mut self.terminal
    }

    /// The signal (SIGINT, SIGTERM, SIGHUP) that asked the session to end, if one did.
    pub fn signal(&self) -> Option<i32> {
        match self.signal.load(Ordering::SeqCst) {
            0 => None,
            s => i32::try_from(s).ok(),
        }
    }

    /// The next terminal event, waiting at most `timeout`.
    pub fn next_event(&mut self, timeout: Duration) -> Result<Option<Event>> {
        if event::poll(timeout).context("cannot read the terminal")? {
            Ok(Some(event::read().context("cannot read the terminal")?))
        } else {
            Ok(None)
        }
    }
}

/// Ends the process [`GRACE`] after a signal unless `ended` is set by then (see the module doc).
fn watchdog(signal: Arc<AtomicUsize>, ended: Arc<AtomicBool>) {
    std::thread::spawn(move || {
        let mut since: Option<Instant> = None;
        while !ended.load(Ordering::SeqCst) {
            let sig = signal.load(Ordering::SeqCst);
            if sig != 0 {
                let at = *since.get_or_insert_with(Instant::now);
                if at.elapsed() >= GRACE {
                    restore();
                    std::process::exit(128 + i32::try_from(sig).unwrap_or(0));
                }
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    });
}

impl Drop for Session {
    fn drop(&mut self) {
        self.ended.store(true, Ordering::SeqCst);
        restore();
        #[cfg(unix)]
        for id in self.handlers.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}

/// A key the commands act on; key releases and repeats of unhandled keys are `None`.
pub fn key(event: &Event) -> Option<KeyEvent> {
    match event {
        Event::Key(k) if k.kind != KeyEventKind::Release => Some(*k),
        _ => None,
    }
}

/// Whether `key` is Ctrl-C, which raw mode delivers as a key instead of a signal.
pub fn is_ctrl_c(key: &KeyEvent) -> bool {
    key.modifiers.contains(KeyModifiers::CONTROL) && matches!(key.code, KeyCode::Char('c'))
}
