//! The same seed gives the same stream whatever the chunking, start offset or thread count.

use crate::common;

use common::{busy_scene, sensor};
use tofprobe_scene::{BLOCK_PULSES, PhotonSource};

const N: usize = 150_000;

fn src(seed: u64) -> PhotonSource {
    PhotonSource::new(&sensor(50.0, 0.3, 0.3), &busy_scene(), seed).expect("valid source")
}

fn chunked(s: &PhotonSource, first: u64, n: usize, chunk: usize) -> Vec<Option<u32>> {
    let mut out = vec![None; n];
    for (i, c) in out.chunks_mut(chunk).enumerate() {
        s.fill(first + (i * chunk) as u64, c);
    }
    out
}

#[test]
fn chunk_size_does_not_change_the_stream() {
    let s = src(42);
    let whole = chunked(&s, 0, N, N);
    for chunk in [1000, BLOCK_PULSES, 5000, 65536] {
        assert_eq!(chunked(&s, 0, N, chunk), whole, "chunk {chunk}");
    }
    // Tiny odd chunks regenerate their block each time: checked on a shorter prefix.
    assert_eq!(
        chunked(&s, 0, 3 * BLOCK_PULSES, 7),
        whole[..3 * BLOCK_PULSES]
    );
    // A request starting mid-block equals the same slice of the whole record.
    let mut tail = vec![None; 10_000];
    s.fill(12_345, &mut tail);
    assert_eq!(tail, whole[12_345..22_345]);
    // for_each_chunk streams the same record.
    let mut streamed = Vec::with_capacity(N);
    s.for_each_chunk(N as u64, 3000, |first, c| {
        assert_eq!(first as usize, streamed.len());
        streamed.extend_from_slice(c);
    });
    assert_eq!(streamed, whole);
}

#[test]
fn counts_do_not_depend_on_chunking() {
    let s = src(9);
    let mut out = vec![None; N];
    let whole = s.fill_counted(0, &mut out);
    let mut sum = tofprobe_scene::FillCounts::default();
    let mut first = 0;
    for c in out.chunks_mut(3001) {
        sum += s.fill_counted(first, c);
        first += c.len() as u64;
    }
    assert_eq!(sum, whole);
    assert!(whole.background_wins > 0 && whole.detections > whole.background_wins);
}

#[test]
fn thread_count_does_not_change_the_stream() {
    let s = src(42);
    let whole = chunked(&s, 0, N, N);
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let mut out = vec![None; N];
        pool.install(|| s.par_fill(0, &mut out));
        assert_eq!(out, whole, "{threads} threads");
        let mut tail = vec![None; N - 777];
        pool.install(|| s.par_fill(777, &mut tail));
        assert_eq!(tail, whole[777..], "{threads} threads, unaligned start");
    }
    assert_eq!(s.record(N as u64), whole);
}

#[test]
fn seeds_give_different_streams() {
    let a = chunked(&src(1), 0, 20_000, 20_000);
    let b = chunked(&src(2), 0, 20_000, 20_000);
    let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
    // Independent streams agree by chance: both None with probability
    // (0.7·e^-0.3)² = 0.27, equal codes rarely (σ = 10 codes wide). 0.35 is > 20 SE away.
    assert!(same < 7_000, "{same} of 20000 equal");
}

/// The compact form (`fill_codes`: the code, or NO_DETECTION) is the same stream as the
/// `Option` form, with the same counts, in any chunking and from mid-block starts.
#[test]
fn the_compact_codes_are_the_same_stream() {
    use tofprobe_scene::NO_DETECTION;
    let s = src(7);
    let whole = chunked(&s, 0, 40_000, 40_000);
    let mut codes = vec![0u32; 40_000];
    for (i, c) in codes.chunks_mut(3001).enumerate() {
        s.fill_codes((i * 3001) as u64, c);
    }
    let as_options: Vec<Option<u32>> = codes
        .iter()
        .map(|&c| (c != NO_DETECTION).then_some(c))
        .collect();
    assert_eq!(as_options, whole);
    assert!(whole.iter().any(Option::is_none) && whole.iter().any(Option::is_some));
    let mut opts = vec![None; 9000];
    let mut tail = vec![0u32; 9000];
    assert_eq!(
        s.fill_counted_codes(12_345, &mut tail),
        s.fill_counted(12_345, &mut opts)
    );
    assert_eq!(&codes[12_345..21_345], &tail[..]);
}
