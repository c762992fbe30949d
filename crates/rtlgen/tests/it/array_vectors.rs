//! The array's vector files (`tofprobe_rtlgen::array_vectors`) on a hand-made trace, line
//! by line against the format testbench/array_harness.cpp and array_tb.v read
//! (docs/pixel-contract.md "Array"), and the stimulus thinning (`exercise`) against its
//! closed form: every count of valid SPADs from none to all, each SPAD the only one in turn.

use tofprobe_rtlgen::array_vectors::{
    ArrayPorts, ArrayTrace, FILES, digest, exercise, vector_files,
};

#[test]
fn a_one_by_two_trace_writes_the_files_the_testbenches_read() {
    let port = |pulse_o, ro_valid, ro_data| ArrayPorts {
        pulse_o,
        ready: true,
        ro_valid,
        ro_data,
    };
    let words = vec![vec![vec![0x1f, 0x2], vec![0x3, 0xabc]]];
    let trace = ArrayTrace {
        bits: 12,
        superpixel: 1,
        ports: vec![port(true, false, 0), port(false, true, 0xabc)],
        pulses: 2,
        pixels: vec![(0, 1), (0, 0)],
        words: &words,
        reset_at: None,
    };
    // Two pixels, T = 3: pulse 0 pixel 0 detects code 5, pulse 1 pixel 1 code 7.
    let detections = vec![vec![Some(5), None], vec![None, Some(7)]];
    let files = vector_files(&trace, &detections, 3, "top_array", "// h");
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, FILES);
    let text = |k: usize| files[k].1.lines().collect::<Vec<_>>();
    assert_eq!(
        text(0),
        [
            "// h",
            "`define AR_NP 2",
            "`define AR_T 3",
            "`define AR_B 12",
            "`define AR_CYCLES 2",
            "`define AR_PULSES 2",
            "`define AR_TOP top_array"
        ]
    );
    // P·(T+1) = 8 bits {tdc[5:0], valid[1:0]}, pixel i's code at bits 2 + 3i: pulse 0 is
    // 5 << 2 | 0b01 = 0x15, pulse 1 is 7 << 5 | 0b10 = 0xe2; two hex digits a line.
    assert_eq!(text(1), ["// h", "15", "e2"]);
    assert_eq!(text(2), ["// h", "1 1 0 0", "0 1 1 abc"]);
    // Readout order: the pixels' (row, col) as given, their words in hex.
    assert_eq!(&text(3)[2..], ["0 0 1: 1f 2", "0 0 0: 3 abc"]);
    assert_eq!(
        text(4)[2],
        format!("0 0 1 {:016x}", digest(&[0x1f, 0x2])),
        "the digest is FNV-1a 64 of the words' little-endian bytes"
    );
    assert_eq!(digest(&[]), 0xcbf2_9ce4_8422_2325);
    // A mid-frame reset adds its cycle; G = 2 the SPAD inputs.
    let trace = ArrayTrace {
        superpixel: 2,
        reset_at: Some(9),
        ..trace
    };
    let four = vec![vec![None; 2]; 4];
    let params = vector_files(&trace, &four, 3, "t", "// h").remove(0).1;
    assert!(
        params.contains("`define AR_NS 4\n`define AR_NP 1\n"),
        "{params}"
    );
    assert!(params.ends_with("`define AR_RESET_AT 9\n"), "{params}");
}

#[test]
fn exercise_reaches_every_count_of_valid_spads_and_each_spad_alone() {
    // One superpixel of G = 2 (four SPADs, one pixel a row): all valid on 10 pulses.
    let mut inputs = vec![vec![Some(1u32); 10]; 4];
    exercise(&mut inputs, 1, 2);
    for n in 0..10 {
        let valid: Vec<usize> = inputs
            .iter()
            .enumerate()
            .filter(|(_, d)| d.get(n).copied().flatten().is_some())
            .map(|(s, _)| s)
            .collect();
        // k = n mod 5 SPADs kept, from position n mod 4 on.
        let k = n % 5;
        let want: Vec<usize> = {
            let mut v: Vec<usize> = (0..k).map(|i| (n + i) % 4).collect();
            v.sort_unstable();
            v
        };
        assert_eq!(valid, want, "pulse {n}");
    }
    // G = 1: pixel p keeps pulse n when (n + p) is odd.
    let mut pixels = vec![vec![Some(3u32); 4]; 2];
    exercise(&mut pixels, 2, 1);
    assert_eq!(pixels[0], [None, Some(3), None, Some(3)]);
    assert_eq!(pixels[1], [Some(3), None, Some(3), None]);
    // A shape that does not tile the inputs is left alone.
    let mut odd = vec![vec![Some(1u32); 3]; 3];
    exercise(&mut odd, 2, 1);
    assert!(odd.iter().flatten().all(Option::is_some));
}
