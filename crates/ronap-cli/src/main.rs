//! `ronap`: the command-line front of ronap-core (the library of this crate).

fn main() -> std::process::ExitCode {
    ronap_cli::main()
}
