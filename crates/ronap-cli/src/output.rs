//! Output helpers of the binary: progress bars, closed pipes, Ctrl-C, clock time for file names;
//! atomic writing itself lives in `ronap_core::io` ([`ronap_core::io::write_atomic`]).

use std::io::Write as _;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Whether `e` comes from writing to a closed pipe (`ronap ... | head`), which is not an error.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// A progress bar on stderr counting to `len` with `template` (indicatif's), labelled `prefix`;
/// hidden when stderr is not a terminal, so logs and pipes get no bar.
pub fn progress_bar(len: u64, template: &str, prefix: String) -> indicatif::ProgressBar {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use std::io::IsTerminal;
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    let style =
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style.with_key(
        "per_sec",
        |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = w.write_str(&rate(state.per_sec()));
        },
    ));
    bar.set_prefix(prefix);
    bar
}

/// A rate as a progress bar shows it: `2576/s`, `42.5/s`, `0.25/s`.
pub fn rate(per_sec: f64) -> String {
    match per_sec {
        r if !r.is_finite() => "-/s".to_string(),
        r if r >= 100.0 => format!("{r:.0}/s"),
        r if r >= 1.0 => format!("{r:.1}/s"),
        r => format!("{r:.2}/s"),
    }
}

/// A flag the first interrupt sets (after saying `what` happens now), so the run stops cleanly and
/// keeps everything. An interrupt is Ctrl-C (SIGINT) or a termination request (SIGTERM, as
/// `timeout`, schedulers and service managers send, or SIGHUP). Signals that come together (as
/// `timeout` sends one to the process and one to its process group) count once: a repeat quits at
/// once, with code 130, only when it is a Ctrl-C from a terminal at least a second after the first.
pub fn cancel_on_ctrl_c(what: &'static str) -> Arc<AtomicBool> {
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        use std::io::IsTerminal;
        if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            let terminal = std::io::stdin().is_terminal() || std::io::stderr().is_terminal();
            std::thread::spawn(move || {
                let mut first = None;
                for signal in signals.forever() {
                    match first {
                        None => {
                            first = Some(std::time::Instant::now());
                            flag.store(true, Ordering::SeqCst);
                            let again = if terminal {
                                " (Ctrl-C again to quit now)"
                            } else {
                                ""
                            };
                            // A closed terminal (SIGHUP) must not end this thread.
                            let _ =
                                writeln!(std::io::stderr(), "\nronap: interrupted; {what}{again}");
                        }
                        Some(at) => {
                            if should_quit_now(signal, terminal, at) {
                                std::process::exit(130);
                            }
                        }
                    }
                }
            });
        }
    }
    #[cfg(not(unix))]
    {
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
            eprintln!("\nronap: interrupted; {what} (Ctrl-C again to quit now)");
        });
    }
    cancel
}

/// Whether a repeated interrupt `signal`, coming after the first one (at `first`), means "quit
/// now": only a terminal's Ctrl-C, a second or more after the first.
#[cfg(unix)]
fn should_quit_now(signal: i32, terminal: bool, first: std::time::Instant) -> bool {
    signal == signal_hook::consts::SIGINT
        && terminal
        && first.elapsed() >= std::time::Duration::from_secs(1)
}

/// `n` and `noun`, plural but for one: "1 thread", "2 threads".
pub fn counted(n: impl Into<u64>, noun: &str) -> String {
    match n.into() {
        1 => format!("1 {noun}"),
        n => format!("{n} {noun}s"),
    }
}

/// `2026-11-21T10:31:05Z` style UTC parts from the system clock.
pub fn utc_now() -> (i64, u32, u32, u32, u32, u32) {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Howard Hinnant's civil-from-days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (
        year,
        month,
        day,
        (rem / 3600) as u32,
        (rem / 60 % 60) as u32,
        (rem % 60) as u32,
    )
}

/// `base`, or `base-2`, `base-3`... the first that does not exist yet.
pub fn unused_dir(base: String) -> std::path::PathBuf {
    use std::path::PathBuf;
    (1..)
        .map(|k| {
            if k == 1 {
                PathBuf::from(&base)
            } else {
                PathBuf::from(format!("{base}-{k}"))
            }
        })
        .find(|p| !p.exists())
        .unwrap_or_else(|| PathBuf::from(base))
}

/// Checks before any work is spent that `--out` (`path`, a file) can be written: not a
/// directory (`example` names a file to give instead, such as `policy.safetensors`), in a
/// directory that exists and takes files, and, unless `force`, not there already (weights and
/// labelled rows cost time to make again).
pub fn check_out_file(path: &std::path::Path, force: bool, example: &str) -> anyhow::Result<()> {
    if path.is_file() && !force {
        anyhow::bail!(
            "--out {}: the file exists; --force replaces it, or give another --out",
            path.display()
        );
    }
    if path.is_dir() || path.as_os_str().to_string_lossy().ends_with('/') {
        anyhow::bail!(
            "--out {}: is a directory; give a file name such as {}",
            path.display(),
            path.join(example).display()
        );
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "--out {}: directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    // The file is written through a temporary file in that directory: try one.
    if let Err(e) = ronap_core::io::check_writable(dir) {
        anyhow::bail!("--out {}: {e}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rate_shows_whole_steps_when_fast_and_decimals_only_when_slow() {
        assert_eq!(rate(2575.5969), "2576/s");
        assert_eq!(rate(42.46), "42.5/s");
        assert_eq!(rate(0.254), "0.25/s");
        assert_eq!(rate(f64::INFINITY), "-/s");
    }

    #[cfg(unix)]
    #[test]
    fn only_a_terminals_ctrl_c_a_second_later_quits_at_once() {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use std::time::{Duration, Instant};
        let long_ago = Instant::now() - Duration::from_secs(2);
        assert!(should_quit_now(SIGINT, true, long_ago));
        // Signals that come together (timeout's to the process and to its group) count once.
        assert!(!should_quit_now(SIGINT, true, Instant::now()));
        assert!(!should_quit_now(SIGTERM, true, long_ago));
        assert!(!should_quit_now(SIGINT, false, long_ago));
    }
}
