//! Output helpers of the binary: progress bars, closed pipes, Ctrl-C, clock time for file names;
//! atomic writing itself lives in `ronap_core::io::atomic`.

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
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_prefix(prefix);
    bar
}

/// A flag the first Ctrl-C sets (after saying `what` happens now); a second Ctrl-C exits at once
/// with code 130. A termination request (SIGTERM, as `timeout`, schedulers and service managers
/// send, or SIGHUP) counts as a Ctrl-C, so what is done is kept then too.
pub fn cancel_on_ctrl_c(what: &'static str) -> Arc<AtomicBool> {
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nronap: interrupted; {what} (Ctrl-C again to quit now)");
    });
    cancel
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
