//! Labelled data for behaviour cloning, the top layer: an expert planner labelling the states a
//! driver visits ([`expert`]), and a person at the keys ([`human`]), both writing the data-log
//! rows of `io::datalog`. Uses every layer below it.

pub mod expert;
pub mod human;
