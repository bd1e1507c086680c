//! Issue 26 §4: a UTF-8 byte-order mark before a program (`%NAME G71 *` with an editor's
//! BOM in front) is read, and the patch writes it back: the output is the BOM followed by
//! exactly what the same program without it gives.

use polepatch::PatchOptions;
use polepatch::kinematics::Machine;
use std::path::PathBuf;

#[test]
fn a_utf8_bom_before_the_program_is_read_and_kept() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let plain = std::fs::read(root.join("fixtures/c17/SING.I")).unwrap();
    let mut with_bom = b"\xEF\xBB\xBF".to_vec();
    with_bom.extend_from_slice(&plain);
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let opts = PatchOptions::default();
    let (out_plain, rep_plain) = polepatch::patch_nc(&plain, &m, &opts).unwrap();
    let (out_bom, rep_bom) = polepatch::patch_nc(&with_bom, &m, &opts).unwrap();
    assert_eq!(&out_bom[..3], b"\xEF\xBB\xBF");
    assert_eq!(&out_bom[3..], &out_plain[..]);
    assert_eq!(rep_bom.zones.len(), rep_plain.zones.len());
    assert!(
        rep_bom
            .zones
            .iter()
            .all(|z| z.outcome == polepatch::Outcome::Reached)
    );
}

/// Issue 42 item 5: the same with a program named `T` (`%T G71 *`): the mark made the
/// first line start with bytes the lexer did not know, its `%` began no header, and `T`
/// was read as a tool word without a number. The mark is before the first line now.
#[test]
fn a_utf8_bom_before_a_program_named_t() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sing = std::fs::read_to_string(root.join("fixtures/c17/SING.I")).unwrap();
    let plain = sing.replace("%SING G71 *", "%T G71 *").into_bytes();
    assert!(plain.starts_with(b"%T G71 *"));
    let mut with_bom = b"\xEF\xBB\xBF".to_vec();
    with_bom.extend_from_slice(&plain);
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let opts = PatchOptions::default();
    let (out_plain, rep_plain) = polepatch::patch_nc(&plain, &m, &opts).unwrap();
    let (out_bom, rep_bom) = polepatch::patch_nc(&with_bom, &m, &opts).unwrap();
    assert_eq!(&out_bom[..3], b"\xEF\xBB\xBF");
    assert_eq!(&out_bom[3..], &out_plain[..]);
    assert_eq!(rep_bom.zones.len(), rep_plain.zones.len());
    assert!(rep_plain.words_changed > 0);
}
