//! Bad input: each error names the value, the 1-based line and the byte column of the
//! word's letter.

use polepatch_nc::{Dialect, Flags, ParseError, parse};

fn err(src: &[u8]) -> ParseError {
    parse(src.to_vec(), Dialect::Auto).expect_err("should be rejected")
}

#[test]
fn malformed_number() {
    let e = err(b"%P G71 *\nN10 G01 X+1 *\nN20 X+2 Y+0 Z-8 A+1 C12..5 *\n");
    assert_eq!((e.line, e.column), (3, 21));
    assert_eq!(e.message, "C value '12..5' is not a number");
    assert_eq!(
        e.clone().with_path("SING.I").to_string(),
        "SING.I:3:21: C value '12..5' is not a number"
    );
}

#[test]
fn non_finite_values() {
    let e = err(b"G1 X1\nG1 CNaN\n");
    assert_eq!(
        (e.line, e.column, e.message.as_str()),
        (2, 4, "C value 'NaN' is not a finite number")
    );
    let e = err(b"N1 G1 C=inf\n");
    assert_eq!(
        (e.line, e.column, e.message.as_str()),
        (1, 7, "C value 'inf' is not a finite number")
    );
}

/// An expression or a variable on an axis or feed word is not an error: the block is
/// kept, flagged, and its run listed as not analysable by the library.
#[test]
fn expression_on_an_axis_word_flags_the_block() {
    let p = parse(
        b"; sinumerik\r\nN10 TRAORI\r\nN20 G1 X=IC(5) Y0\r\n".to_vec(),
        Dialect::Auto,
    )
    .unwrap();
    assert!(p.blocks[2].flags.has(Flags::NOT_ANALYSABLE));
    let p = parse(b"G1 F#100\n".to_vec(), Dialect::Auto).unwrap();
    assert!(p.blocks[0].flags.has(Flags::NOT_ANALYSABLE));
    // Garbage is not an expression.
    let e = err(b"G1 X1\nG1 C\xfc\n");
    assert_eq!((e.line, e.column), (2, 4));
    assert!(e.message.contains("is not a number"), "{}", e.message);
}

#[test]
fn letter_without_number() {
    let e = err(b"G1 X\n");
    assert_eq!(
        (e.line, e.column, e.message.as_str()),
        (1, 4, "X word has no number")
    );
    let e = err(b"G1 Y1\nG1 X+ Y2\n");
    assert_eq!(
        (e.line, e.column, e.message.as_str()),
        (2, 4, "X value '+' is not a number")
    );
    // Last line without a newline.
    let e = err(b"G1 X1\nG1 Z");
    assert_eq!((e.line, e.column), (2, 4));
}

#[test]
fn identifiers_and_comments_are_not_errors() {
    for ok in [
        &b"N10 TRAORI\nN20 CYCLE800(0,\"TC1\",1)\nN30 MSG(\"X\")\nN40 G1 X=1 ; X\n"[..],
        b"(X)\nG1 X1. (C12..5)\n",
        b"%X\nN10 G1 X1 * C12..5\n",
        b"N1 G1 X1 ; \xff\xfe C12..5\n",
    ] {
        parse(ok.to_vec(), Dialect::Auto).unwrap();
    }
}
