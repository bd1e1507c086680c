# Convenience recipes (optional: every command here is plain cargo; `just` is not required).

# Run the whole test suite (the README's test command).
test:
    cargo test --workspace

# Lints as CI runs them.
lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets -- -D warnings

# Analyse the bundled singular program on the UCP710.
analyze-example:
    cargo run --release -- analyze fixtures/c17/SING.I --machine mikron-ucp710

# criterion benches.
bench:
    cargo bench -p polepatch-benches
