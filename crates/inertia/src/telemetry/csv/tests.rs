//! The reader's input rules: strict header, no comment lines, bounded lines and
//! messages, leap seconds.

use super::*;
use nalgebra::Vector3;
use std::io::Read;

const HEADER: &str = "t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z";

fn row(t: &str) -> String {
    format!("{t},0,0,0,1,0,0,0")
}

fn read(text: &str) -> Result<Vec<Sample>, TelemetryError> {
    TelemetryReader::new(text.as_bytes(), "f.csv", CsvOptions::default())?.collect()
}

#[test]
fn a_duplicated_column_is_an_error_naming_both_positions() {
    let text = format!("{HEADER},rho_x\n{},5\n", row("0"));
    let e = read(&text).unwrap_err();
    assert!(matches!(
        e,
        TelemetryError::DuplicateColumn {
            first: 6,
            second: 9,
            ..
        }
    ));
    assert_eq!(
        e.to_string(),
        "f.csv:1: column `rho_x` appears twice (columns 6 and 9)"
    );
}

#[test]
fn a_line_starting_with_hash_is_an_error_not_a_comment() {
    let text = format!("{HEADER}\n{}\n#{}\n{}\n", row("0"), row("0.1"), row("0.2"));
    let e = read(&text).unwrap_err();
    assert_eq!(e.line(), Some(3), "{e}");
    assert!(e.to_string().contains("starts with `#`"), "{e}");
    // Blank lines hold nothing and are skipped.
    let text = format!("{HEADER}\n{}\n\n{}\n", row("0"), row("0.1"));
    assert_eq!(read(&text).unwrap().len(), 2);
}

#[test]
fn a_line_without_end_fails_after_the_limit_not_at_end_of_file() {
    // An endless line: before the cap this read until memory ran out.
    let endless = std::io::repeat(b'a');
    let e = TelemetryReader::new(endless, "f.csv", CsvOptions::default())
        .err()
        .unwrap();
    assert!(matches!(
        e,
        TelemetryError::LineTooLong {
            line: 1,
            limit: MAX_LINE_BYTES,
            ..
        }
    ));
    // In the data: named with its line.
    let head = format!("{HEADER}\n{}\n", row("0"));
    let endless = head.as_bytes().chain(std::io::repeat(b'1'));
    let mut r = TelemetryReader::new(endless, "f.csv", CsvOptions::default()).unwrap();
    assert!(r.next().unwrap().is_ok());
    let e = r.next().unwrap().unwrap_err();
    assert_eq!(e.line(), Some(3), "{e}");
    assert!(e
        .to_string()
        .starts_with("f.csv:3: line longer than 1048576 bytes"));
    // A line just under the limit is read.
    let pad = "x".repeat(MAX_LINE_BYTES - HEADER.len() - 1);
    let text = format!("{HEADER},{pad}\n{},0\n", row("0"));
    assert_eq!(read(&text).unwrap().len(), 1);
}

#[test]
fn messages_quote_bounded_content() {
    // A 500 kB header without the needed columns, a 500 kB field.
    let wide = "c".repeat(500_000);
    let e = read(&format!("{wide}\n1\n")).unwrap_err();
    let m = e.to_string();
    assert!(m.len() < 400, "{} bytes", m.len());
    assert!(m.contains("…"), "{m}");
    let e = read(&format!("{HEADER}\n{}\n", row(&wide))).unwrap_err();
    let m = e.to_string();
    assert!(m.len() < 400 && m.contains("(500000 bytes)"), "{m}");
}

#[test]
fn times_in_messages_are_compact() {
    let text = format!(
        "{HEADER}\n{}\n{}\n",
        row("9876543210.123456789"),
        row("299.8999999999997")
    );
    let m = read(&text).unwrap_err().to_string();
    assert_eq!(
        m,
        "f.csv:3: column `t`: time 299.9 s does not increase (previous row: 9876543210.12 s)"
    );
}

#[test]
fn iso_time_stamps_count_the_leap_second() {
    let stamps = [
        "2016-12-31T23:59:59.8Z",
        "2016-12-31T23:59:59.9Z",
        "2016-12-31T23:59:60.0Z",
        "2016-12-31T23:59:60.1Z",
        "2016-12-31T23:59:60.9Z",
        "2017-01-01T00:00:00.0Z",
        "2017-01-01T00:00:00.1Z",
    ];
    let text: String = std::iter::once(HEADER.to_string())
        .chain(stamps.iter().map(|s| row(s)))
        .map(|l| l + "\n")
        .collect();
    let t: Vec<f64> = read(&text).unwrap().iter().map(|s| s.t_s).collect();
    let want = [0.0, 0.1, 0.2, 0.3, 1.1, 1.2, 1.3];
    for (a, b) in t.iter().zip(want) {
        assert!((a - b).abs() < 1e-9, "{t:?}");
    }
    // Second 60 anywhere else is refused with the line.
    let text = format!("{HEADER}\n{}\n", row("2016-12-31T12:00:60Z"));
    let e = read(&text).unwrap_err();
    assert!(e.to_string().contains("23:59:60"), "{e}");
}

#[test]
fn outside_columns_are_read_and_a_blank_one_is_named() {
    let text = "t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,r_x,r_y,r_z,b_x,b_y,b_z,f_x,f_y,f_z\n\
                0,0,0,0,1,0,0,0,7e6,0,0,1e-5,2e-5,3e-5,0,0,1\n\
                0.1,0,0,0,1,0,0,0,7e6,1,0,1e-5,2e-5,3e-5,0,0,0\n";
    let s = read(text).unwrap();
    assert_eq!(s[1].external.position_m, Some(Vector3::new(7e6, 1.0, 0.0)));
    assert_eq!(s[0].external.field_t, Some(Vector3::new(1e-5, 2e-5, 3e-5)));
    assert_eq!(s[0].external.force_n, Some(Vector3::new(0.0, 0.0, 1.0)));
    let blank = "t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z,f_x,f_y,f_z\n\
                 0,0,0,0,1,0,0,0,0,0,1\n\
                 0.1,0,0,0,1,0,0,0,,,\n";
    let e = read(blank).unwrap_err().to_string();
    assert!(e.contains("f.csv:3: column `f_x`"), "{e}");
    assert!(e.contains("forces (f_x,f_y,f_z) missing here"), "{e}");
}
