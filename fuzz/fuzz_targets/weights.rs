//! A weights file (`--policy mlp:FILE`): parsed; a network that loads is run on a few
//! observations and written back, which must read as the same network.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ronap_core::policy::Mlp;

fuzz_target!(|data: &[u8]| {
    let Ok(mlp) = Mlp::from_bytes(data) else {
        return;
    };
    let n = mlp.inputs();
    if n > 100_000 {
        return;
    }
    for fill in [0.0, 1.0, -1.0, 1e30, f32::NAN] {
        let observation = vec![fill; n];
        let _ = mlp.forward(&observation);
        let _ = mlp.action(&observation);
    }
    let bytes = mlp.to_bytes().expect("a loaded network writes");
    let again = Mlp::from_bytes(&bytes).expect("a written network reads");
    assert_eq!(again.to_bytes().expect("writes again"), bytes);
});
