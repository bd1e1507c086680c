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

/// Issue 42 item 1: `…Z55.455\rN85X…` in a file otherwise LF is one block to an
/// LF-terminated controller, so an X twice in it is an error — which says that a carriage
/// return is inside the line, where, and that editors show two lines there. Also in a
/// file read on several threads (the same message from every reader).
#[test]
fn a_lone_cr_inside_a_line_is_named_in_the_error() {
    let text = b"%CR G71 *\nN10 G01 X+0 Y+0 Z+50 A+5 C+0 F1000 *\nN84 X+12.1 Y-3.5 Z+55.455\rN85 X+13.2 *\nN90 M30 *\n";
    let e = err(text);
    assert_eq!((e.line, e.column), (3, 31));
    assert!(
        e.message
            .starts_with("X appears twice in this block (first at col 5)")
            && e.message
                .contains("line 3 holds a carriage return (CR) at col 26")
            && e.message.contains("most editors show it as two lines"),
        "{}",
        e.message
    );
    // Without the CR (two lines) the program reads.
    let two = String::from_utf8_lossy(text).replace('\r', " *\n");
    parse(two.into_bytes(), Dialect::Auto).unwrap();
    // An error before the CR is not about it.
    let e = err(b"G1 X1\nG1 X1..2 Y2\rZ3\n");
    assert_eq!(e.message, "X value '1..2' is not a number");
    // The parallel reader (a file larger than a window) says the same.
    let mut big = Vec::new();
    while big.len() < 600 << 10 {
        big.extend_from_slice(b"G1 X1 Y2 Z3 A4 C5 F100\n");
    }
    let line = big.iter().filter(|&&b| b == b'\n').count() + 1;
    big.extend_from_slice(b"X1 Z55.455\rX2\n");
    let e = polepatch_nc::scan(&big, Dialect::Fanuc, |_, _, _| {
        std::ops::ControlFlow::Continue(())
    })
    .expect_err("X twice");
    assert_eq!((e.line, e.column), (line, 12));
    assert!(
        e.message.contains("carriage return (CR) at col 11"),
        "{}",
        e.message
    );
}

/// Issue 42 item 5: a UTF-8 byte-order mark before `%T G71 *` (a Heidenhain ISO program
/// named T) was read as part of the first line, whose `%` then began no header: "T word has
/// no number". The mark belongs to no line: the program reads as it does without it, in
/// every dialect whose detection looks at the first line.
#[test]
fn a_byte_order_mark_before_the_first_line() {
    let programs: [&[u8]; 4] = [
        b"%T G71 *\nN10 G01 X+0 Y+0 Z+5 A+5 C+0 F1000 *\nN20 X+1 A+4 C+10 *\n%T G71 *\n",
        b"%T G71\nN10 G01 X+0 Y+0 Z+5 A+5 C+0 F1000\nN20 X+1 A+4 C+10\n",
        b"0  BEGIN PGM T MM\n1  L  X+0 Y+0 Z+5 A+5 C+0 R0 F1000\n2  L  X+1 A+4 C+10\n3  END PGM T MM\n",
        b"T1 M6\nG1 X0 Y0 Z5 A5 C0 F1000\nX1 A4 C10\n",
    ];
    for plain in programs {
        let mut bom = b"\xEF\xBB\xBF".to_vec();
        bom.extend_from_slice(plain);
        let a = parse(plain.to_vec(), Dialect::Auto).unwrap();
        let b = parse(bom, Dialect::Auto).unwrap_or_else(|e| {
            panic!("{}: {e}", String::from_utf8_lossy(plain));
        });
        assert_eq!(a.dialect, b.dialect, "{}", String::from_utf8_lossy(plain));
        assert_eq!(a.blocks.len(), b.blocks.len());
        for k in 0..a.blocks.len() {
            assert_eq!(a.state(k).pos, b.state(k).pos, "block {k}");
        }
        // Columns are the editor's: the first line's words start after the mark.
        assert_eq!(b.blocks[0].span().start, 3);
    }
}
