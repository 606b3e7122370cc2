//! Unit and property tests of the matrix formats.

use std::io::Cursor;

use proptest::prelude::*;

use super::*;
use crate::header::Header;

fn write_mem(m: &Matrix, opts: &WriteOptions) -> Vec<u8> {
    m.write(Vec::new(), opts).unwrap()
}

fn read_mem(bytes: Vec<u8>) -> anyhow::Result<Matrix> {
    Matrix::read_from(MatrixReader::from_reader(Cursor::new(bytes), "mem")?)
}

fn mat(nrows: usize, ncols: usize, ncomp: usize, data: Vec<f64>) -> Matrix {
    Matrix {
        nrows,
        ncols,
        ncomp,
        data,
        header: Header::new(),
        format: DataFormat::Ascii,
        notes: Vec::new(),
    }
}

#[test]
fn rmtxop_float_header_bytes() {
    // `rmtxop -ff -` on a 1×2×3 input, piped (verified against Radiance).
    let m = mat(1, 2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let out = write_mem(
        &m,
        &WriteOptions::with_command(DataFormat::Float, "rmtxop -ff -"),
    );
    let head =
        b"#?RADIANCE\nrmtxop -ff -\nNROWS=1\nNCOLS=2\nNCOMP=3\nBigEndian=0\nFORMAT=float\n\n";
    assert_eq!(&out[..head.len()], head);
    assert_eq!(out.len(), head.len() + 24);
}

#[test]
fn padding_aligns_binary_data() {
    let m = mat(1, 1, 1, vec![1.0]);
    for (fmt, align) in [(DataFormat::Float, 4), (DataFormat::Double, 8)] {
        for start in 0..8u64 {
            let mut o = WriteOptions::with_command(fmt, "x");
            o.align_from = Some(start);
            let out = write_mem(&m, &o);
            let hdr = out.len() - fmt.value_size().unwrap();
            assert_eq!((start as usize + hdr) % align, 0);
            let back = read_mem(out).unwrap();
            assert_eq!(back.data, vec![1.0]);
        }
    }
}

#[test]
fn ascii_layouts() {
    let m = mat(1, 2, 3, vec![1.0, 2.0, 3.0, 0.5, -0.25, 1e-30]);
    let mut o = WriteOptions {
        header: None,
        ..Default::default()
    };
    assert_eq!(
        String::from_utf8(write_mem(&m, &o)).unwrap(),
        " 1.0000000e+00 2.0000000e+00 3.0000000e+00\t 5.0000000e-01 -2.5000000e-01 1.0000000e-30\t\n"
    );
    o.ascii = AsciiLayout::Dctimestep;
    assert_eq!(
        String::from_utf8(write_mem(&m, &o)).unwrap(),
        "1.000000e+00 2.000000e+00 3.000000e+00\t5.000000e-01 -2.500000e-01 1.000000e-30\n"
    );
    o.ascii = AsciiLayout::Rcontrib;
    assert_eq!(
        String::from_utf8(write_mem(&m, &o)).unwrap(),
        "1.000000e+00\t2.000000e+00\t3.000000e+00\t5.000000e-01\t-2.500000e-01\t1.000000e-30\t\n"
    );
}

#[test]
fn c_formatting() {
    let mut s = String::new();
    format_c_e(&mut s, 1.5e-300, 3);
    s.push('|');
    format_c_e(&mut s, 0.0, 2);
    s.push('|');
    format_c_e(&mut s, 123456.0, 0);
    assert_eq!(s, "1.500e-300|0.00e+00|1e+05");
    let g = |v: f64, p: usize| {
        let mut s = String::new();
        format_c_g(&mut s, v, p);
        s
    };
    assert_eq!(g(0.5, 3), "0.5");
    assert_eq!(g(1234.5, 3), "1.23e+03");
    assert_eq!(g(0.0001234, 3), "0.000123");
    assert_eq!(g(0.00001234, 3), "1.23e-05");
    assert_eq!(g(100.0, 3), "100");
    assert_eq!(g(0.0, 3), "0");
}

#[test]
fn ascii_reader_ignores_line_structure_and_divides_exposure() {
    let text = b"#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=1\nEXPOSURE=2\nFORMAT=ascii\n\n2 4\n\n 6\t8\n"
        .to_vec();
    let m = read_mem(text).unwrap();
    assert_eq!(m.data, vec![1.0, 2.0, 3.0, 4.0]);
    assert!(m.header.is_empty());
}

#[test]
fn nrows_inferred_for_binary_files_and_streams() {
    let mut body = b"#?RADIANCE\nNCOLS=2\nNCOMP=1\nFORMAT=double\n\n".to_vec();
    for v in [1.0f64, 2.0, 3.0, 4.0, 5.0, 6.0] {
        body.extend_from_slice(&v.to_le_bytes());
    }
    let m = read_mem(body.clone()).unwrap();
    assert_eq!((m.nrows, m.ncols), (3, 2));
    let dir = std::env::temp_dir().join(format!("fen-fmt-infer-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("m.bin");
    std::fs::write(&p, &body).unwrap();
    let r = MatrixReader::open(p.to_str().unwrap()).unwrap();
    assert_eq!(r.info.nrows, Some(3));
    // Half a row too many: not inferable.
    body.extend_from_slice(&7.0f64.to_le_bytes());
    std::fs::write(&p, &body).unwrap();
    assert!(MatrixReader::open(p.to_str().unwrap()).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn huge_nrows_is_not_allocated_up_front() {
    let mut body = b"NROWS=4000000000000\nNCOLS=1\nNCOMP=1\nFORMAT=float\n\n".to_vec();
    body.extend_from_slice(&1.0f32.to_le_bytes());
    let e = read_mem(body).unwrap_err().to_string();
    assert!(e.contains("unexpected end of data after 1 of"), "{e}");
    let e = read_mem(b"NROWS=1\nNCOLS=4000000000000\nNCOMP=3\nFORMAT=float\n\n".to_vec())
        .unwrap_err()
        .to_string();
    assert!(e.contains("too large"), "{e}");
}

#[test]
fn bad_inputs_give_clear_errors() {
    let cases: &[(&[u8], &str)] = &[
        (b"NROWS=1\nNCOLS=1\nFORMAT=weird\n\n", "unknown data format"),
        (b"NROWS=1\nNCOMP=1\nFORMAT=ascii\n\n1\n", "missing NCOLS"),
        (
            b"NROWS=2\nNCOLS=2\nNCOMP=1\nFORMAT=ascii\n\n1 2 3\n",
            "row 2",
        ),
        (
            b"NROWS=1\nNCOLS=1\nNCOMP=1\nFORMAT=ascii\n\nabc\n",
            "bad number 'abc'",
        ),
        (b"NROWS=x\nNCOLS=1\nFORMAT=ascii\n\n", "NROWS=x"),
        (
            b"NROWS=1\nNCOLS=2\nNCOMP=1\nFORMAT=float\n\n\0\0\0\0\0\0",
            "6 of 8 bytes",
        ),
        (
            b"NCOMP=3\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 -X 3\n",
            "resolution string",
        ),
    ];
    for (data, want) in cases {
        let e = format!("{:#}", read_mem(data.to_vec()).unwrap_err());
        assert!(e.contains(want) && e.contains("mem"), "{e} (wanted {want})");
    }
}

#[test]
fn rgbe_matrix_round_trip_with_resolution_string() {
    let data: Vec<f64> = (0..2 * 20 * 3).map(|i| (i % 7) as f64 * 0.5).collect();
    let m = mat(2, 20, 3, data.clone());
    let out = write_mem(&m, &WriteOptions::with_command(DataFormat::Rgbe, "x"));
    let text = String::from_utf8_lossy(&out);
    assert!(
        text.contains("FORMAT=32-bit_rle_rgbe\n\n-Y        2 +X       20\n"),
        "{text}"
    );
    assert!(!text.contains("NROWS"));
    let back = read_mem(out).unwrap();
    assert_eq!((back.nrows, back.ncols, back.ncomp), (2, 20, 3));
    for (a, b) in data.iter().zip(&back.data) {
        // RGBE keeps 8 bits of mantissa relative to the largest component.
        assert!((a - b).abs() <= 3.0 / 256.0 * 2.0, "{a} {b}");
    }
}

#[test]
fn big_endian_files_are_swapped() {
    let mut body = b"NROWS=1\nNCOLS=2\nNCOMP=1\nBigEndian=1\nFORMAT=float\n\n".to_vec();
    body.extend_from_slice(&1.5f32.to_be_bytes());
    body.extend_from_slice(&(-2.0f32).to_be_bytes());
    assert_eq!(read_mem(body).unwrap().data, vec![1.5, -2.0]);
}

#[test]
fn transpose_keeps_components_together() {
    let m = mat(2, 3, 2, (0..12).map(|v| v as f64).collect());
    let t = m.transpose();
    assert_eq!((t.nrows, t.ncols), (3, 2));
    assert_eq!(t.get(2, 1), m.get(1, 2));
    assert_eq!(t.transpose(), m);
}

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        Just(0.0),
        Just(-0.0),
        Just(f64::MIN_POSITIVE),
        Just(5e-324),
        Just(1e-310),
        Just(f64::MAX),
        Just(1e300),
        Just(-1e-300),
        (-1e6f64..1e6),
    ]
}

fn matrix_strategy() -> impl Strategy<Value = Matrix> {
    (
        1usize..5,
        1usize..7,
        prop_oneof![Just(1usize), Just(3), Just(5)],
    )
        .prop_flat_map(|(r, c, k)| {
            proptest::collection::vec(value(), r * c * k).prop_map(move |d| mat(r, c, k, d))
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn double_round_trips_exactly(m in matrix_strategy(), be in any::<bool>(), nrows in any::<bool>()) {
        let mut o = WriteOptions::with_command(DataFormat::Double, "t");
        o.big_endian = be;
        o.write_nrows = nrows;
        let back = read_mem(write_mem(&m, &o)).unwrap();
        prop_assert_eq!((back.nrows, back.ncols, back.ncomp), (m.nrows, m.ncols, m.ncomp));
        for (a, b) in m.data.iter().zip(&back.data) {
            prop_assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    #[test]
    fn float_round_trips_to_f32(m in matrix_strategy(), be in any::<bool>()) {
        let mut o = WriteOptions::with_command(DataFormat::Float, "t");
        o.big_endian = be;
        let back = read_mem(write_mem(&m, &o)).unwrap();
        for (a, b) in m.data.iter().zip(&back.data) {
            prop_assert_eq!((*a as f32).to_bits(), (*b as f32).to_bits());
            prop_assert_eq!(*b, *a as f32 as f64);
        }
    }

    #[test]
    fn ascii_round_trips_to_8_digits(m in matrix_strategy(), layout in 0..3usize) {
        let mut o = WriteOptions::with_command(DataFormat::Ascii, "t");
        o.ascii = [AsciiLayout::Rmtxop, AsciiLayout::Dctimestep, AsciiLayout::Rcontrib][layout];
        let back = read_mem(write_mem(&m, &o)).unwrap();
        prop_assert_eq!(back.data.len(), m.data.len());
        let digits = if layout == 0 { 7 } else { 6 };
        for (a, b) in m.data.iter().zip(&back.data) {
            // %.Ne keeps N+1 significant digits: half a unit in the last one.
            let tol = a.abs() * 0.5 * 10f64.powi(-digits) * 1.0000001;
            prop_assert!((a - b).abs() <= tol, "{} {}", a, b);
        }
    }

    #[test]
    fn reader_never_panics_on_mutated_input(
        m in matrix_strategy(),
        fmt in 0..4usize,
        cuts in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
        trunc in any::<prop::sample::Index>(),
    ) {
        let f = [DataFormat::Ascii, DataFormat::Float, DataFormat::Double, DataFormat::Rgbe][fmt];
        let m = if f.is_picture() { mat(m.nrows, m.ncols, 3, m.data.iter().cycle().take(m.nrows * m.ncols * 3).cloned().collect()) } else { m };
        let mut bytes = write_mem(&m, &WriteOptions::with_command(f, "t"));
        for (i, b) in cuts {
            let k = i.index(bytes.len());
            bytes[k] = b;
        }
        let keep = trunc.index(bytes.len() + 1);
        bytes.truncate(keep);
        let _ = read_mem(bytes);
    }
}

#[test]
fn reading_returns_its_warnings_instead_of_printing_them() {
    let m =
        read_mem(b"#?RADIANCE\nNROWS=2\nNCOLS=1\nNCOMP=1\nFORMAT=ascii\n\n1\nnan\n3\n".to_vec())
            .unwrap();
    assert_eq!(m.data.len(), 2);
    assert_eq!(m.notes.len(), 2, "{:?}", m.notes);
    assert!(m.notes[0].contains("row 2") && m.notes[0].contains("not a finite number"));
    assert!(
        m.notes[1].contains("data beyond the 2 rows"),
        "{:?}",
        m.notes
    );
    let clean = read_mem(b"#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=1\nFORMAT=ascii\n\n1\n".to_vec());
    assert!(clean.unwrap().notes.is_empty());
}

#[test]
fn a_sink_hears_warnings_before_a_later_error() {
    static HEARD: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    fn sink(msg: String) {
        HEARD.lock().unwrap().push(msg);
    }
    // row 2 is not a number, then the data stops a row short of NROWS
    let text = b"#?RADIANCE\nNROWS=3\nNCOLS=1\nNCOMP=1\nFORMAT=ascii\n\n1\nnan\n".to_vec();
    let r = MatrixReader::from_reader(Cursor::new(text), "mem")
        .unwrap()
        .report_to(sink);
    assert!(Matrix::read_from(r).is_err());
    let heard = HEARD.lock().unwrap();
    assert_eq!(heard.len(), 1, "{heard:?}");
    assert!(heard[0].contains("row 2") && heard[0].contains("not a finite number"));
}
