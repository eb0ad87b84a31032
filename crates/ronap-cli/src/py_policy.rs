//! `--policy py:FILE.py:FUNCTION`: a Python function as a policy, run in a Python process per
//! worker thread and spoken to over pipes, so the `ronap` binary needs no Python to build.
//!
//! Each step sends the observation as one line of numbers, then ` | ` and what a team robot
//! received (`<count>` broadcasts of `<from> <x> <y> <heading> <goal x> <goal y> <message...>`);
//! the process answers `A <index>` for an action (with ` M <floats>` for a message), `BAD <repr>`
//! for a value that is not one, or `ERR <message>` when the function raised. The interpreter is
//! `$RONAP_PYTHON`, else `python3`; the observation reaches the function as a float32 numpy array
//! when numpy is installed, else as a list.
//!
//! With `ronap run --batch N` one process serves every worker: a line `B <rows> <width> <values>`
//! carries the observations of the episodes waiting for an action, the function gets them as a
//! `(rows, width)` array and returns one action per row, answered `A <index> <index> ...`.
//!
//! A function of one argument gets the observation and returns an action. A function of two gets
//! the observation and the team's inbox (a list of dicts: `from`, `pose`, `goal`, `message`,
//! nearest sender first; empty for a lone robot) and returns an action or `(action, message)`.

use ronap_core::policy::{
    BatchPolicy, Batched, Decision, Policy, PolicyError, PolicyFactory, Rows,
};
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
import inspect
try:
    params = [p for p in inspect.signature(fn).parameters.values()
              if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.VAR_POSITIONAL)]
    listens = len(params) >= 2 or any(p.kind == p.VAR_POSITIONAL for p in params)
except (TypeError, ValueError):
    listens = False
def arr(values):
    return np.asarray(values, dtype=np.float32) if np is not None else values
def index_of(a):
    # An integer (numpy's too), or a whole float such as a network's argmax; never a bool.
    if isinstance(a, bool) or type(a).__name__ in ("bool_", "bool"):
        return None
    try:
        return a.__index__()
    except Exception:
        try:
            whole = float(a) if getattr(a, "shape", ()) == () else None
        except Exception:
            whole = None
        if whole is not None and whole == whole and whole % 1 == 0 and abs(whole) < 1e15:
            return int(whole)
    return None
say("READY")
for line in sys.stdin:
    if line.startswith("B "):
        # A batch: rows, width, then the observations row after row; one action per row back.
        words = line.split()
        rows, width = int(words[1]), int(words[2])
        values = [float(x) for x in words[3:]]
        obs = np.asarray(values, dtype=np.float32).reshape(rows, width) if np is not None else \
            [values[r * width:(r + 1) * width] for r in range(rows)]
        try:
            a = fn(obs)
        except Exception as e:
            say(f"ERR {e!r}")
            continue
        try:
            items = list(a.tolist() if hasattr(a, "tolist") else a)
        except Exception:
            items = None
        indices = None if items is None or len(items) != rows else [index_of(x) for x in items]
        if indices is None or any(i is None for i in indices):
            say(f"BAD {a!r}")
        else:
            say("A " + " ".join(str(i) for i in indices))
        continue
    head, _, tail = line.partition("|")
    obs = arr([float(x) for x in head.split()])
    try:
        if listens:
            words = tail.split()
            count, size, at, inbox = int(words[0]), int(words[1]), 2, []
            for _ in range(count):
                v = [float(x) for x in words[at:at + 6 + size]]
                at += 6 + size
                inbox.append({"from": int(v[0]), "pose": (v[1], v[2], v[3]), "goal": (v[4], v[5]),
                              "message": arr(v[6:])})
            a = fn(obs, inbox)
        else:
            a = fn(obs)
    except Exception as e:
        say(f"ERR {e!r}")
        continue
    message = None
    if listens and isinstance(a, (tuple, list)) and len(a) == 2:
        a, message = a
    index = index_of(a)
    if index is None:
        say(f"BAD {a!r}")
        continue
    if message is None:
        say(f"A {index}")
        continue
    try:
        floats = [float(x) for x in (message.tolist() if hasattr(message, "tolist") else message)]
    except Exception:
        say(f"BADM {message!r}")
        continue
    say(f"A {index} M " + " ".join(repr(x) for x in floats))
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
        let mut command = Command::new(&self.python);
        // A process group of its own: the signals a terminal or `timeout` sends ronap's group
        // are ronap's to handle (it stops cleanly, then ends the process), not the policy's.
        #[cfg(unix)]
        std::os::unix::process::CommandExt::process_group(&mut command, 0);
        let mut child = command
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
            inbox: "0 0".into(),
            message: Vec::new(),
        };
        match process.read()?.as_str() {
            "READY" => Ok(process),
            other => Err(other.strip_prefix("ERR ").unwrap_or(other).to_string()),
        }
    }
}

impl PyPolicyFactory {
    /// The function as a batched policy (`ronap run --batch N`): one Python process, called with
    /// an `(n, observation size)` array of the episodes waiting for an action, n up to `rows`.
    pub fn batched(&self, rows: usize) -> Result<Batched, String> {
        Ok(Batched::new(
            Box::new(self.spawn()?),
            rows,
            PolicyFactory::name(self),
        ))
    }
}

impl BatchPolicy for PyProcess {
    fn act_batch(&mut self, batch: Rows<'_>, actions: &mut Vec<Action>) -> Result<(), PolicyError> {
        let (observations, width, rows) = (batch.values, batch.width, batch.count());
        let mut line = String::with_capacity(observations.len() * 12 + 16);
        line.push_str(&format!("B {rows} {width}"));
        for v in observations {
            line.push_str(&format!(" {v:?}"));
        }
        line.push('\n');
        let answer = self.ask(&line)?;
        let expected = format!("expected {rows} actions, each 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)");
        if let Some(rest) = answer.strip_prefix("A ") {
            for word in rest.split_whitespace() {
                let action = word
                    .parse::<usize>()
                    .ok()
                    .and_then(DiscreteAction::from_index)
                    .ok_or_else(|| {
                        PolicyError::Failed(format!("returned action {word}, {expected}"))
                    })?;
                actions.push(Action::Discrete(action));
            }
            Ok(())
        } else {
            Err(refused(&answer, &expected))
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
    /// What the robot received, as the next request sends it.
    inbox: String,
    /// The message of the last answer.
    message: Vec<f32>,
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

impl PyProcess {
    /// Sends `line` (a request ending in a line break) and reads the answer.
    fn ask(&mut self, line: &str) -> Result<String, PolicyError> {
        self.stdin
            .write_all(line.as_bytes())
            .map_err(|e| PolicyError::Failed(format!("cannot write to the Python process: {e}")))?;
        self.read().map_err(PolicyError::Failed)
    }
}

/// What an answer other than an action (`BAD <repr>`, `ERR <message>`, anything else) means;
/// `expected` says what an action is.
fn refused(answer: &str, expected: &str) -> PolicyError {
    PolicyError::Failed(if let Some(repr) = answer.strip_prefix("BAD ") {
        format!("returned {repr}, {expected}")
    } else if let Some(message) = answer.strip_prefix("ERR ") {
        format!("raised {message}")
    } else {
        format!("unexpected answer {answer:?} from the Python process")
    })
}

impl Drop for PyProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Policy for PyProcess {
    fn reset(&mut self, _world: &World, _episode: &Episode) -> Result<(), PolicyError> {
        self.inbox = "0 0".into();
        self.message.clear();
        Ok(())
    }

    fn hear(&mut self, inbox: ronap_core::sim::Inbox<'_>) {
        let size = inbox.get(0).map_or(0, |b| b.message.len());
        let mut text = format!("{} {size}", inbox.len());
        for b in inbox {
            text.push_str(&format!(
                " {} {:?} {:?} {:?} {:?} {:?}",
                b.from, b.pose.x, b.pose.y, b.pose.z_deg, b.goal.x, b.goal.y
            ));
            for m in &b.message {
                text.push_str(&format!(" {m:?}"));
            }
        }
        self.inbox = text;
    }

    fn message(&mut self, out: &mut [f32]) {
        for (o, m) in out.iter_mut().zip(&self.message) {
            *o = *m;
        }
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let mut line = String::with_capacity(256);
        for v in episode.observation() {
            line.push_str(&format!("{v:?} "));
        }
        line.push_str("| ");
        line.push_str(&self.inbox);
        line.push('\n');
        let answer = self.ask(&line)?;
        let expected = "expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)";
        if let Some(rest) = answer.strip_prefix("A ") {
            let (index, message) = rest.split_once(" M ").unwrap_or((rest, ""));
            self.message.clear();
            for x in message.split_whitespace() {
                match x.parse::<f32>() {
                    Ok(v) if v.is_finite() => self.message.push(v),
                    _ => {
                        return Err(PolicyError::Failed(format!(
                            "returned the message value {x}, expected finite numbers"
                        )))
                    }
                }
            }
            let action = index
                .parse::<usize>()
                .ok()
                .and_then(DiscreteAction::from_index)
                .ok_or_else(|| PolicyError::Failed(format!("returned {index}, {expected}")))?;
            Ok(Decision::Act(Action::Discrete(action)))
        } else if let Some(repr) = answer.strip_prefix("BADM ") {
            Err(PolicyError::Failed(format!(
                "returned the message {repr}, expected numbers"
            )))
        } else {
            Err(refused(&answer, expected))
        }
    }
}

/// Python processes kept between team episodes, so a batched team spawns one per worker, not
/// one per episode.
#[derive(Clone, Default)]
pub struct ProcessPool(std::sync::Arc<std::sync::Mutex<Vec<PyProcess>>>);

impl PyPolicyFactory {
    /// A team policy for `ronap run --batch` on a team scenario: the robots `batched` marks are
    /// decided by one call of the function a step, with the `(n, observation size)` array of
    /// those running (n up to the team's size); robot `k` of the others by `others[k]`. Its
    /// process comes from `pool` (or is started) and goes back there when the episode ends.
    pub fn batched_team(
        &self,
        pool: &ProcessPool,
        batched: Vec<bool>,
        others: Vec<Option<Box<dyn Policy>>>,
    ) -> Result<ronap_core::policy::Joint, PolicyError> {
        let idle = pool.0.lock().ok().and_then(|mut p| p.pop());
        let process = match idle {
            Some(p) => p,
            None => self.spawn().map_err(PolicyError::Failed)?,
        };
        let pooled = Pooled {
            process: Some(process),
            pool: pool.clone(),
        };
        Ok(ronap_core::policy::Joint::new(
            Box::new(pooled),
            batched,
            others,
        ))
    }
}

/// A Python process of a pool, handed back to the pool when its team episode ends (unless it
/// failed).
struct Pooled {
    process: Option<PyProcess>,
    pool: ProcessPool,
}

impl Drop for Pooled {
    fn drop(&mut self) {
        if let (Some(p), Ok(mut pool)) = (self.process.take(), self.pool.0.lock()) {
            pool.push(p);
        }
    }
}

impl BatchPolicy for Pooled {
    fn act_batch(&mut self, rows: Rows<'_>, actions: &mut Vec<Action>) -> Result<(), PolicyError> {
        let process = self
            .process
            .as_mut()
            .ok_or_else(|| PolicyError::Failed("no Python process".into()))?;
        let result = process.act_batch(rows, actions);
        if result.is_err() {
            // A process that failed (or exited) is not handed to the next episode.
            self.process = None;
        }
        result
    }
}
