//! A configuration file (`--config`), parsed and checked as every command does, its errors
//! located and printed; a valid one printed back as `ronap config` does and read again, which
//! must give the same configuration.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::config::ConfigFile;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = ConfigFile::from_text(Path::new("/fuzz/config.toml"), text.to_string());
    let sim = match file.parse() {
        Ok(sim) => sim,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    match sim.clone().validate() {
        Ok(valid) => {
            let printed = valid.as_sim_config().to_documented_toml();
            let again = ConfigFile::from_text(Path::new("/fuzz/printed.toml"), printed.clone())
                .parse()
                .unwrap_or_else(|e| {
                    panic!("ronap config printed a file it cannot read: {e}\n{printed}")
                });
            assert_eq!(
                &again,
                valid.as_sim_config(),
                "printed and read back:\n{printed}"
            );
        }
        Err(e) => {
            let _ = file.locate(e).to_string();
        }
    }
});
