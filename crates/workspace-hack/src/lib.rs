//! Nothing to use: this crate only asks for the union of the features ronap's builds need of
//! some shared dependencies, so `cargo build`, `cargo test` and `maturin develop` compile them
//! (and ronap-core above them) once between them. See its `Cargo.toml`.
#![no_std]
