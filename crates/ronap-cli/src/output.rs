//! Output helpers of the binary; atomic writing itself lives in `ronap_core::output`.

/// Whether `e` comes from writing to a closed pipe (`ronap ... | head`), which is not an error.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
