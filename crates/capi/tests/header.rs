//! The committed header `include/polepatch.h` is what cbindgen makes of `src/lib.rs` with
//! `cbindgen.toml`. Regenerate: `UPDATE_HEADER=1 cargo test -p polepatch-capi --test header`.

#[test]
fn committed_header_is_current() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let config = cbindgen::Config::from_file(format!("{dir}/cbindgen.toml")).unwrap();
    let bindings = cbindgen::Builder::new()
        .with_src(format!("{dir}/src/lib.rs"))
        .with_config(config)
        .generate()
        .expect("cbindgen reads src/lib.rs");
    let mut fresh = Vec::new();
    bindings.write(&mut fresh);
    let path = format!("{dir}/include/polepatch.h");
    if std::env::var_os("UPDATE_HEADER").is_some() {
        std::fs::write(&path, &fresh).unwrap();
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/polepatch.h is out of date: UPDATE_HEADER=1 cargo test -p polepatch-capi --test header"
    );
}
