//! ronap-learn: training ronap's learned policies, with candle's tensors and autodiff.
//!
//! Behaviour cloning ([`bc`], the paper's Algorithm 2) fits a classifier to expert or human rows;
//! DQN ([`dqn`], Algorithm 1) learns Q-values from the model's reward while episodes run on every
//! core. Both produce the core's [`ronap_core::policy::Mlp`], saved as a safetensors file
//! that `ronap run --policy mlp:FILE` runs without any ML framework.

pub mod bc;
pub mod dqn;
pub mod net;
pub mod replay;

/// Training that could not go on.
#[derive(Debug, thiserror::Error)]
pub enum LearnError {
    /// A tensor operation failed.
    #[error("tensor error: {0}")]
    Tensor(#[from] candle_core::Error),
    /// The training data cannot be used.
    #[error("training data: {0}")]
    Data(String),
    /// The trained network is not a valid policy network.
    #[error("network: {0}")]
    Network(String),
    /// Training diverged.
    #[error("training diverged: {0}")]
    Diverged(String),
    /// An episode could not start.
    #[error(transparent)]
    Run(#[from] ronap_core::run::RunError),
    /// Worker threads could not start.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
}
