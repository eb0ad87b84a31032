//! Nothing to build: the crate's build-dependencies only unify the features of host crates.
fn main() {
    // Without this line cargo would run the script again, and rebuild every crate above this
    // one, whenever any file of the crate changed.
    println!("cargo::rerun-if-changed=build.rs");
}
