//! Files, above `render`: atomic writes, run directories and their manifest, data logs and step
//! logs. Uses every layer below it; the layers below never touch a file they were not handed.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod atomic;
mod block_run;
mod datalog;
pub(crate) mod fault;
pub(crate) mod figures;
mod lock;
mod manifest;
mod partial;
mod run_dir;
mod steplog;
mod team_rows;
mod training;

// Writing files whole.
pub use atomic::{check_writable, save_image, save_network, write_atomic, OutputError};
// Data logs, the labelled rows of behaviour cloning (`read`, `parse` and `Format` are aliased
// here: the layer reads many formats).
pub use datalog::{
    parse as parse_data_log, read as read_data_log, DataLogError, DataLogWriter, DataSet,
    Format as DataLogFormat, Sample,
};
// Run directories: the manifest, the episode rows, the step logs, training curves.
pub use manifest::{ManifestError, RunManifest, RunPlan, PLAN_FILE};
pub use run_dir::{
    BlockRun, EpisodeRows, Layout, Pictures, ResumeError, RunFiles, RunInfo, RunWriter,
};
pub use steplog::{parse_steps, read_steps, LoggedStep, StepsError};
pub use team_rows::{robot_columns, robot_rows, team_episode_row, TEAM_COLUMNS};
pub use training::{Curves, TrainingLog};

// For the layers above only.
pub(crate) use lock::LOCK_FILE;
pub(crate) use run_dir::{
    finish, lone_headers, manifest, restore, timing_row, Streams, START_GOAL_COLUMNS,
    TIMING_COLUMNS,
};
