//! Files, above `render`: atomic writes, run directories and their manifest, data logs and step
//! logs. Uses every layer below it; the layers below never touch a file they were not handed.

pub mod atomic;
pub mod block_run;
pub mod datalog;
pub(crate) mod fault;
pub mod figures;
pub mod lock;
pub mod manifest;
pub mod partial;
pub mod run_dir;
pub mod steplog;
pub mod team_rows;
pub mod training;
