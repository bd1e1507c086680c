//! The committed fixtures/generated and fixtures/shop sets are exactly what the generator
//! writes today.

use std::path::PathBuf;
use std::process::Command;

#[test]
fn committed_fixtures_match_the_generator() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = std::env::temp_dir().join(format!("polepatch-fixturegen-{}", std::process::id()));
    let shop = dir.join("shop");
    let status = Command::new(env!("CARGO_BIN_EXE_polepatch-fixturegen"))
        .arg(&dir)
        .arg(&shop)
        .status()
        .unwrap();
    assert!(status.success());
    let mut shop_names: Vec<_> = std::fs::read_dir(&shop)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    shop_names.sort();
    assert_eq!(shop_names.len(), 16);
    for n in shop_names {
        let fresh = std::fs::read(shop.join(&n)).unwrap();
        let committed = std::fs::read(root.join("fixtures/shop").join(&n)).unwrap_or_else(|_| {
            panic!(
                "fixtures/shop/{} is missing: rerun `cargo run -p polepatch-fixturegen -- \
                 fixtures/generated fixtures/shop`",
                n.to_string_lossy()
            )
        });
        assert!(
            fresh == committed,
            "fixtures/shop/{} differs from the generator's output",
            n.to_string_lossy()
        );
    }
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.path().is_file())
        .map(|e| e.file_name())
        .collect();
    names.sort();
    assert_eq!(names.len(), 96);
    for n in names {
        let fresh = std::fs::read(dir.join(&n)).unwrap();
        let committed = std::fs::read(root.join("fixtures/generated").join(&n))
            .unwrap_or_else(|_| panic!("fixtures/generated/{} is missing: rerun `cargo run -p polepatch-fixturegen -- fixtures/generated`", n.to_string_lossy()));
        assert!(
            fresh == committed,
            "fixtures/generated/{} differs from the generator's output",
            n.to_string_lossy()
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
