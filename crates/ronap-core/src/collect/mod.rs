//! Labelled data for behaviour cloning, the top layer: an expert planner labelling the states a
//! driver visits ([`collect`]), and a person at the keys ([`HumanCollector`]), both writing the
//! data-log rows of `io::datalog`. Uses every layer below it.
//!
//! The files are private: what other crates use is re-exported here, so a file can move without
//! breaking anyone.

mod expert;
mod human;

pub use expert::{collect, collect_episode, CollectError, Collection, Posing};
// A human step's outcome, aliased: `eval` has an `Outcome` of its own.
pub use human::{HumanCollector, Outcome as HumanOutcome};
