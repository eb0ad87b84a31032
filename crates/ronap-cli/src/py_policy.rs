//! `--policy py:FILE.py:FUNCTION`: a Python function as a policy, run in a Python process per
//! worker thread and spoken to over pipes, so the `ronap` binary needs no Python to build.
//!
//! Each step sends the observation as one line of numbers; the process answers `A <index>` for an
//! action, `BAD <repr>` for a value that is not one, or `ERR <message>` when the function raised.
//! The interpreter is `$RONAP_PYTHON`, else `python3`; the observation reaches the function as a
//! float32 numpy array when numpy is installed, else as a list.

use ronap_core::policy::{Decision, Policy, PolicyError, PolicyFactory};
use ronap_core::{Action, DiscreteAction, Episode, World};
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

/// The driver the Python process runs: load the function, then answer one line per step.
const DRIVER: &str = r#"
import importlib.util, sys
path, name = sys.argv[1], sys.argv[2]
out = sys.stdout
def say(text):
    out.write(text.replace("\n", " ") + "\n")
    out.flush()
try:
    spec = importlib.util.spec_from_file_location("ronap_user_policy", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    fn = getattr(module, name)
    if not callable(fn):
        raise TypeError(f"{name} is not callable")
except BaseException as e:
    say(f"ERR cannot load {name} from {path}: {e!r}")
    sys.exit(0)
try:
    import numpy as np
except ImportError:
    np = None
say("READY")
for line in sys.stdin:
    obs = [float(x) for x in line.split()]
    if np is not None:
        obs = np.asarray(obs, dtype=np.float32)
    try:
        a = fn(obs)
    except Exception as e:
        say(f"ERR {e!r}")
        continue
    if isinstance(a, bool) or not hasattr(a, "__index__"):
        say(f"BAD {a!r}")
    else:
        say(f"A {a.__index__()}")
"#;

/// Makes Python policies from `py:FILE:FUNCTION`.
pub struct PyPolicyFactory {
    python: String,
    file: PathBuf,
    function: String,
}

impl PyPolicyFactory {
    /// Parses `FILE:FUNCTION` (after `py:`) and checks, by starting one process, that the function
    /// loads.
    pub fn new(spec: &str) -> Result<Self, String> {
        let (file, function) = spec
            .rsplit_once(':')
            .filter(|(f, n)| !f.is_empty() && !n.is_empty())
            .ok_or_else(|| format!("--policy py:{spec}: expected py:FILE.py:FUNCTION"))?;
        let file = PathBuf::from(file);
        if !file.is_file() {
            return Err(format!(
                "--policy py:{spec}: no such file {}",
                file.display()
            ));
        }
        let factory = Self {
            python: std::env::var("RONAP_PYTHON").unwrap_or_else(|_| "python3".into()),
            file,
            function: function.to_string(),
        };
        factory
            .spawn()
            .map_err(|e| format!("--policy py:{spec}: {e}"))?;
        Ok(factory)
    }

    fn spawn(&self) -> Result<PyProcess, String> {
        let mut child = Command::new(&self.python)
            .args(["-u", "-c", DRIVER])
            .arg(&self.file)
            .arg(&self.function)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", self.python))?;
        let stdin = child.stdin.take().ok_or("no pipe to the Python process")?;
        let stdout = BufReader::new(
            child
                .stdout
                .take()
                .ok_or("no pipe from the Python process")?,
        );
        let mut process = PyProcess {
            child,
            stdin,
            stdout,
            line: String::new(),
        };
        match process.read()?.as_str() {
            "READY" => Ok(process),
            other => Err(other.strip_prefix("ERR ").unwrap_or(other).to_string()),
        }
    }
}

impl PolicyFactory for PyPolicyFactory {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        Ok(Box::new(self.spawn().map_err(PolicyError::Failed)?))
    }

    fn name(&self) -> String {
        format!("py:{}:{}", self.file.display(), self.function)
    }
}

/// One Python process answering for one worker.
struct PyProcess {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    line: String,
}

impl PyProcess {
    fn read(&mut self) -> Result<String, String> {
        self.line.clear();
        match self.stdout.read_line(&mut self.line) {
            Ok(0) => Err("the Python process exited".into()),
            Ok(_) => Ok(self.line.trim_end().to_string()),
            Err(e) => Err(format!("cannot read from the Python process: {e}")),
        }
    }
}

impl Drop for PyProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Policy for PyProcess {
    fn reset(&mut self, _world: &World, _episode: &Episode) -> Result<(), PolicyError> {
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let mut line = String::with_capacity(256);
        for v in episode.observation() {
            line.push_str(&format!("{v:?} "));
        }
        line.push('\n');
        self.stdin
            .write_all(line.as_bytes())
            .map_err(|e| PolicyError::Failed(format!("cannot write to the Python process: {e}")))?;
        let answer = self.read().map_err(PolicyError::Failed)?;
        let expected = "expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)";
        if let Some(index) = answer.strip_prefix("A ") {
            let action = index
                .parse::<usize>()
                .ok()
                .and_then(DiscreteAction::from_index)
                .ok_or_else(|| PolicyError::Failed(format!("returned {index}, {expected}")))?;
            Ok(Decision::Act(Action::Discrete(action)))
        } else if let Some(repr) = answer.strip_prefix("BAD ") {
            Err(PolicyError::Failed(format!("returned {repr}, {expected}")))
        } else if let Some(message) = answer.strip_prefix("ERR ") {
            Err(PolicyError::Failed(format!("raised {message}")))
        } else {
            Err(PolicyError::Failed(format!(
                "unexpected answer {answer:?} from the Python process"
            )))
        }
    }
}
