//! The time-tagged record decoder and its replay: synthetic records with known fields
//! (every format's bit layout and overflow rule), the real sample files (counts checked
//! against their headers' closed forms), bad input, and the pulse stream against a naive
//! in-memory reference.

use std::path::{Path, PathBuf};

use tofprobe_scene::SceneError;
use tofprobe_scene::tttr::{self, Event, PulseStream, RecordFormat, ReplayOptions, TdcWindow};

/// PicoQuant's sample files vendored in `third_party/picoquant-tttr` (BSD-3-Clause).
fn shared(name: &str) -> PathBuf {
    tofprobe_testkit::data::tttr_record(name)
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// A PTU file with the given record type, resolutions and records.
fn ptu(name: &str, rec_type: u32, res_s: f64, global_s: f64, words: &[u32]) -> PathBuf {
    ptu_with(name, rec_type, res_s, global_s, words.len() as i64, words)
}

fn ptu_with(name: &str, rec_type: u32, res: f64, glob: f64, n: i64, words: &[u32]) -> PathBuf {
    let mut b = Vec::new();
    b.extend_from_slice(b"PQTTTR\0\0");
    b.extend_from_slice(b"1.0.00\0\0");
    let mut tag = |ident: &str, ty: u32, v: [u8; 8], payload: &[u8]| {
        let mut id = [0u8; 32];
        id[..ident.len()].copy_from_slice(ident.as_bytes());
        b.extend_from_slice(&id);
        b.extend_from_slice(&(-1i32).to_le_bytes());
        b.extend_from_slice(&ty.to_le_bytes());
        b.extend_from_slice(&v);
        b.extend_from_slice(payload);
    };
    tag(
        "File_Comment",
        0x4001_FFFF,
        8u64.to_le_bytes(),
        b"synth\0\0\0",
    );
    tag(
        "File_Wide",
        0x4002_FFFF,
        4u64.to_le_bytes(),
        &[b'a', 0, 0, 0],
    );
    tag("File_Flag", 0x0000_0008, 1u64.to_le_bytes(), &[]);
    tag("File_Date", 0x2100_0008, 45000.5f64.to_le_bytes(), &[]);
    tag("Arr", 0x2001_FFFF, 16u64.to_le_bytes(), &[0u8; 16]);
    tag("Blob", 0xFFFF_FFFF, 3u64.to_le_bytes(), &[1, 2, 3]);
    tag("Bits", 0x1100_0008, 5u64.to_le_bytes(), &[]);
    tag("Col", 0x1200_0008, 5u64.to_le_bytes(), &[]);
    tag(
        "TTResultFormat_TTTRRecType",
        0x1000_0008,
        u64::from(rec_type).to_le_bytes(),
        &[],
    );
    tag(
        "TTResultFormat_BitsPerRecord",
        0x1000_0008,
        32u64.to_le_bytes(),
        &[],
    );
    tag("MeasDesc_Resolution", 0x2000_0008, res.to_le_bytes(), &[]);
    tag(
        "MeasDesc_GlobalResolution",
        0x2000_0008,
        glob.to_le_bytes(),
        &[],
    );
    tag(
        "TTResult_SyncRate",
        0x1000_0008,
        10_000_000u64.to_le_bytes(),
        &[],
    );
    tag(
        "MeasDesc_AcquisitionTime",
        0x1000_0008,
        1000u64.to_le_bytes(),
        &[],
    );
    tag(
        "TTResult_NumberOfRecords",
        0x1000_0008,
        n.to_le_bytes(),
        &[],
    );
    tag("Header_End", 0xFFFF_0008, [0; 8], &[]);
    for w in words {
        b.extend_from_slice(&w.to_le_bytes());
    }
    let p = tmp(name);
    std::fs::write(&p, b).unwrap();
    p
}

fn events(p: &Path) -> Vec<Event> {
    tttr::open(p)
        .unwrap()
        .collect::<Result<Vec<_>, _>>()
        .unwrap()
}

fn err(r: Result<impl std::fmt::Debug, SceneError>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn picoharp_t3_fields_and_overflow() {
    // chan 1, dtime 300, nsync 7; an overflow (chan 15, dtime 0); a marker (chan 15,
    // dtime 4) at nsync 9; chan 2, dtime 5, nsync 3 → sync 65536 + 3.
    let w = [
        (1 << 28) | (300 << 16) | 7,
        0xF << 28,
        (0xF << 28) | (4 << 16) | 9,
        (2 << 28) | (5 << 16) | 3,
    ];
    let p = ptu("ph_t3.ptu", 0x0001_0303, 4e-12, 1e-7, &w);
    assert_eq!(
        events(&p),
        vec![
            Event::T3Photon {
                sync: 7,
                channel: 1,
                dtime: 300
            },
            Event::Overflow { wraps: 1 },
            Event::Marker {
                time: 65536 + 9,
                bits: 4
            },
            Event::T3Photon {
                sync: 65536 + 3,
                channel: 2,
                dtime: 5
            },
        ]
    );
}

#[test]
fn picoharp_t2_wrap_is_210698240() {
    let w = [(1 << 28) | 1000, 0xF << 28, 0x0000_0020, (0xF << 28) | 2];
    let p = ptu("ph_t2.ptu", 0x0001_0203, 4e-12, 4e-12, &w);
    assert_eq!(
        events(&p),
        vec![
            Event::T2Photon {
                time: 1000,
                channel: 1
            },
            Event::Overflow { wraps: 1 },
            Event::T2Photon {
                time: 210_698_240 + 32,
                channel: 0
            },
            Event::Marker {
                time: 210_698_240 + 2,
                bits: 2
            },
        ]
    );
}

#[test]
fn hydraharp_t3_overflow_counts_v1_v2() {
    let special = 1u32 << 31;
    let ovf = |n: u32| special | (0x3F << 25) | n;
    let photon = |chan: u32, dtime: u32, nsync: u32| (chan << 25) | (dtime << 10) | nsync;
    let w = [photon(2, 12345, 1000), ovf(0), ovf(3), photon(0, 7, 5)];
    // v1: every overflow record is one wrap, whatever its nsync field says.
    let v1 = events(&ptu("hh1_t3.ptu", 0x0001_0304, 1e-12, 1e-7, &w));
    assert_eq!(
        v1[3],
        Event::T3Photon {
            sync: 2 * 1024 + 5,
            channel: 0,
            dtime: 7
        }
    );
    // v2 and TimeHarp: the count is in nsync, 0 meaning 1.
    for (name, code) in [
        ("hh2", 0x0101_0304),
        ("thn", 0x0001_0305),
        ("thp", 0x0001_0306),
    ] {
        let ev = events(&ptu(&format!("{name}_t3.ptu"), code, 1e-12, 1e-7, &w));
        assert_eq!(
            ev[0],
            Event::T3Photon {
                sync: 1000,
                channel: 2,
                dtime: 12345
            }
        );
        assert_eq!(ev[2], Event::Overflow { wraps: 3 });
        assert_eq!(
            ev[3],
            Event::T3Photon {
                sync: 4 * 1024 + 5,
                channel: 0,
                dtime: 7
            }
        );
    }
}

#[test]
fn hydraharp_t2_sync_marker_overflow() {
    let special = 1u32 << 31;
    let w = [
        special | 100,              // sync at 100
        (3 << 25) | 150,            // photon channel 3
        special | (0x3F << 25) | 2, // v2: 2 wraps of 2^25; v1: one of 33552000
        special | (5 << 25) | 7,    // marker 5
    ];
    let v2 = events(&ptu("hh2_t2.ptu", 0x0101_0204, 1e-12, 1e-12, &w));
    assert_eq!(v2[0], Event::Sync { time: 100 });
    assert_eq!(
        v2[1],
        Event::T2Photon {
            time: 150,
            channel: 3
        }
    );
    assert_eq!(
        v2[3],
        Event::Marker {
            time: 2 * 33_554_432 + 7,
            bits: 5
        }
    );
    let v1 = events(&ptu("hh1_t2.ptu", 0x0001_0204, 1e-12, 1e-12, &w));
    assert_eq!(
        v1[3],
        Event::Marker {
            time: 33_552_000 + 7,
            bits: 5
        }
    );
}

#[test]
fn real_ptu_files_match_their_headers() {
    // (file, format, sync rate Hz, acquisition s, photons): pulses = last sync + 1 must be
    // the acquisition time × sync rate within one overflow period (1024 syncs) and the
    // end of acquisition (ptufile agrees on every count: scripts/tttr-crosscheck.sh).
    for (name, format, photons, records) in [
        (
            "hydraharp_v10_t3.ptu",
            RecordFormat::HydraHarp1T3,
            94_560,
            167_801,
        ),
        (
            "hydraharp_v20_t3.ptu",
            RecordFormat::HydraHarp2T3,
            77_883,
            106_349,
        ),
        (
            "hydraharp_v20_t2.ptu",
            RecordFormat::HydraHarp2T2,
            305_565,
            435_319,
        ),
        (
            "picoharp_v30_t2.ptu",
            RecordFormat::PicoHarpT2,
            920_177,
            929_254,
        ),
    ] {
        let s = tttr::summarize(&shared(name)).unwrap();
        assert_eq!(s.format, format, "{name}");
        assert_eq!(s.counts.records, records, "{name}");
        assert_eq!(s.counts.photons, photons, "{name}");
        assert_eq!(
            s.counts.records,
            s.counts.photons + s.counts.overflow_records + s.counts.markers + s.counts.syncs
        );
        if format.is_t3() {
            let expect = s.sync_rate_hz.unwrap() * s.acquisition_time_s.unwrap();
            let pulses = (s.last_time + 1) as f64;
            assert!(
                (pulses - expect).abs() < 1024.0,
                "{name}: {pulses} vs {expect}"
            );
        }
    }
}

#[test]
fn t3_replay_quantises_like_the_monte_carlo() {
    // 64 ps delay bins, TDC LSB 100 ps over 1000..2000 ps: delays 15 (960 ps, before the
    // window), 16 (1024 ps → code 0), 31 (1984 ps → code 9), 32 (2048 ps, after it).
    let photon = |chan: u32, dtime: u32, nsync: u32| (chan << 25) | (dtime << 10) | nsync;
    let w = [
        photon(0, 31, 2),
        photon(1, 16, 2), // same pulse, earlier: wins
        photon(0, 15, 3), // before the window: no detection
        photon(0, 32, 5), // after it: no detection
        photon(0, 20, 6),
        photon(0, 18, 6),
    ];
    let p = ptu("replay_t3.ptu", 0x0101_0304, 64e-12, 1e-7, &w);
    let win = TdcWindow {
        tdc_lsb_ps: 100.0,
        window_start_ps: 1000.0,
        window_length_ps: 1000.0,
    };
    let mut s = PulseStream::new(tttr::open(&p).unwrap(), &ReplayOptions::new(win)).unwrap();
    let mut out = vec![Some(99); 10];
    assert_eq!(s.fill(&mut out).unwrap(), 7);
    // code = floor((t − 1000)/100): 1024 → 0, 1152 → 1.
    assert_eq!(&out[..7], &[None, None, Some(0), None, None, None, Some(1)]);
    let c = s.counts();
    assert_eq!(
        (c.pulses, c.detections, c.in_window, c.outside_window),
        (7, 2, 4, 2)
    );
    // Only channel 0: pulse 2 is won by the later photon (1984 ps → code 9).
    let mut o = ReplayOptions::new(win);
    o.photon_channel = Some(0);
    let mut s = PulseStream::new(tttr::open(&p).unwrap(), &o).unwrap();
    assert_eq!(s.fill(&mut out).unwrap(), 7);
    assert_eq!(out[2], Some(9));
}

#[test]
fn t2_replay_measures_from_the_last_sync() {
    // PicoHarp T2, 4 ps tags; sync = channel 0. A photon before the first sync is dropped.
    let w = [
        (1 << 28) | 10,   // before any sync
        100,              // sync 0 at 100
        (1 << 28) | 400,  // 300 tags = 1200 ps after sync 0
        1100,             // sync 1
        1200,             // sync 2 (pulse 1 had no photon)
        (1 << 28) | 1210, // 40 ps after sync 2: before the window
    ];
    let p = ptu("replay_t2.ptu", 0x0001_0203, 4e-12, 4e-12, &w);
    let win = TdcWindow {
        tdc_lsb_ps: 50.0,
        window_start_ps: 100.0,
        window_length_ps: 2000.0,
    };
    let mut s = PulseStream::new(tttr::open(&p).unwrap(), &ReplayOptions::new(win)).unwrap();
    let mut out = vec![Some(99); 8];
    assert_eq!(s.fill(&mut out).unwrap(), 3);
    assert_eq!(&out[..3], &[Some(22), None, None]); // (1200 − 100)/50 = 22
    assert_eq!(s.counts().before_first_sync, 1);
    assert_eq!(s.fill(&mut out).unwrap(), 0);
}

#[test]
fn replay_chunking_matches_a_naive_reference_on_a_real_file() {
    // Reference: every photon event in memory, first photon per pulse by a plain loop.
    let path = shared("hydraharp_v20_t3.ptu");
    let win = TdcWindow {
        tdc_lsb_ps: 256.0,
        window_start_ps: 2_000.0,
        window_length_ps: 20_000.0,
    };
    let res_ps = 64.0;
    let all = events(&path);
    let last = tttr::summarize(&path).unwrap().last_time;
    let mut naive: Vec<Option<u32>> = vec![None; last as usize + 1];
    for ev in &all {
        if let Event::T3Photon { sync, dtime, .. } = *ev {
            let t = f64::from(dtime) * res_ps - win.window_start_ps;
            if (0.0..win.window_length_ps).contains(&t) {
                let code = (t / win.tdc_lsb_ps).floor() as u32;
                let slot = &mut naive[sync as usize];
                *slot = Some(slot.map_or(code, |c| c.min(code)));
            }
        }
    }
    for chunk in [1usize, 4096, 1 << 20, 1 << 26] {
        let mut s = PulseStream::new(tttr::open(&path).unwrap(), &ReplayOptions::new(win)).unwrap();
        let mut got = Vec::with_capacity(naive.len());
        s.for_each_chunk(chunk, |first, c| {
            assert_eq!(first as usize, got.len());
            got.extend_from_slice(c);
        })
        .unwrap();
        assert_eq!(got.len(), naive.len(), "chunk {chunk}");
        if let Some(i) = got.iter().zip(&naive).position(|(a, b)| a != b) {
            panic!(
                "chunk {chunk}: pulse {i}: stream {:?}, naive {:?}",
                got[i], naive[i]
            );
        }
        assert!(s.counts().detections > 10_000);
    }
}

#[test]
fn spc_records_and_replay() {
    // Header: clock 125 (12.5 ns). Records: photon (adc 95, route 2, mt 10); MTOV photon
    // (adc 4095, mt 1) → macro 4096 + 1; INVALID|MTOV with 3 overflows; invalid record;
    // marker (route 1) at mt 7; a GAP photon (adc 0, mt 20).
    let rec = |flags: u32, adc: u32, route: u32, mt: u32| {
        (flags << 28) | (adc << 16) | (route << 12) | mt
    };
    let words = [
        125u32,
        rec(0, 95, 2, 10),
        rec(0b0100, 4095, 0, 1),
        (0b1100 << 28) | 3,
        rec(0b1000, 1, 1, 1),
        rec(0b0001, 0, 1, 7),
        rec(0b0010, 0, 0, 20),
    ];
    let p = tmp("synth.spc");
    std::fs::write(
        &p,
        words
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
    let mut r = tttr::open(&p).unwrap();
    let ev: Vec<Event> = r.by_ref().collect::<Result<_, _>>().unwrap();
    let base = 4 * 4096;
    assert_eq!(
        ev,
        vec![
            Event::T3Photon {
                sync: 10,
                channel: 2,
                dtime: 4000
            },
            Event::T3Photon {
                sync: 4097,
                channel: 0,
                dtime: 0
            },
            Event::Overflow { wraps: 3 },
            Event::Marker {
                time: base + 7,
                bits: 1
            },
            Event::T3Photon {
                sync: base + 20,
                channel: 0,
                dtime: 4095
            },
        ]
    );
    let c = r.counts();
    assert_eq!(
        (c.records, c.invalid, c.gaps, c.overflow_wraps),
        (6, 1, 1, 4)
    );
    assert_eq!(r.header().global_resolution_s, Some(12.5e-9));
    // Replay needs the ADC bin, which only the .set file knows.
    let win = TdcWindow {
        tdc_lsb_ps: 1000.0,
        window_start_ps: 0.0,
        window_length_ps: 50_000.0,
    };
    let e = err(PulseStream::new(
        tttr::open(&p).unwrap(),
        &ReplayOptions::new(win),
    ));
    assert!(e.contains("synth.spc") && e.contains("resolution_s"), "{e}");
    let mut o = ReplayOptions::new(win);
    o.resolution_s = Some(10e-12);
    let mut s = PulseStream::new(tttr::open(&p).unwrap(), &o).unwrap();
    let mut out = vec![None; 1 << 15];
    let n = s.fill(&mut out).unwrap();
    assert_eq!(n as u64, base + 21);
    assert_eq!(
        (out[10], out[4097], out[(base + 20) as usize]),
        (Some(40), Some(0), Some(40)) // 4000 · 10 ps, 0 ps, 4095 · 10 ps
    );
}

#[test]
fn bad_input_is_named() {
    // Wrong magic.
    let p = tmp("bad_magic.ptu");
    std::fs::write(&p, b"NOTAPTU\0 1.0.00\0 and some more bytes").unwrap();
    let e = err(tttr::open(&p));
    assert!(
        e.contains("bad_magic.ptu") && e.contains("byte 0") && e.contains("PQTTTR"),
        "{e}"
    );
    // Unknown record type (MultiHarp 0x00010207 is not decoded here).
    let p = ptu("unknown.ptu", 0x0001_0207, 1e-12, 1e-12, &[0]);
    let e = err(tttr::open(&p));
    assert!(
        e.contains("TTResultFormat_TTTRRecType") && e.contains("0x00010207"),
        "{e}"
    );
    // Truncated: the header promises 5 records, the file holds 2 and 3 stray bytes.
    let p = ptu_with("trunc.ptu", 0x0101_0304, 1e-12, 1e-7, 5, &[1, 2]);
    let mut b = std::fs::read(&p).unwrap();
    b.extend_from_slice(&[1, 2, 3]);
    std::fs::write(&p, b).unwrap();
    let e = err(tttr::open(&p).unwrap().collect::<Result<Vec<_>, _>>());
    assert!(
        e.contains("trunc.ptu") && e.contains("record 2") && e.contains("5 records"),
        "{e}"
    );
    assert!(e.contains("truncated"), "{e}");
    // Truncated header.
    let p = tmp("short_header.ptu");
    std::fs::write(
        &p,
        &std::fs::read(shared("picoharp_v30_t2.ptu")).unwrap()[..500],
    )
    .unwrap();
    let e = err(tttr::open(&p));
    assert!(
        e.contains("short_header.ptu") && e.contains("header tag"),
        "{e}"
    );
    // An illegal PicoHarp T3 channel names the record.
    let p = ptu(
        "bad_chan.ptu",
        0x0001_0303,
        4e-12,
        1e-7,
        &[1 << 28, 6 << 28],
    );
    let e = err(tttr::open(&p).unwrap().collect::<Result<Vec<_>, _>>());
    assert!(
        e.contains("record 1 (byte") && e.contains("channel 6"),
        "{e}"
    );
    // A T2 file without sync: real files (HydraHarp v2 T2, TimeHarp 260 N T2).
    let win = TdcWindow {
        tdc_lsb_ps: 8.0,
        window_start_ps: 0.0,
        window_length_ps: 50_000.0,
    };
    for f in [
        shared("hydraharp_v20_t2.ptu"),
        data("timeharp260n_t2_excerpt.ptu"),
    ] {
        let mut s = PulseStream::new(tttr::open(&f).unwrap(), &ReplayOptions::new(win)).unwrap();
        let e = err(s.for_each_chunk(1 << 16, |_, _| {}));
        assert!(e.contains("without sync") && e.contains(".ptu"), "{e}");
    }
    // SPC with a stray partial record.
    let p = tmp("stray.spc");
    std::fs::write(&p, [125u8, 0, 0, 0, 1, 2, 3, 4, 5]).unwrap();
    let e = err(tttr::open(&p).unwrap().collect::<Result<Vec<_>, _>>());
    assert!(
        e.contains("record 1 (byte 8)") && e.contains("stray"),
        "{e}"
    );
    // A window the TDC cannot hold.
    let bad = TdcWindow {
        tdc_lsb_ps: 1.0,
        window_start_ps: 0.0,
        window_length_ps: 1e6,
    };
    let e = err(PulseStream::new(
        tttr::open(&shared("hydraharp_v20_t3.ptu")).unwrap(),
        &ReplayOptions::new(bad),
    ));
    assert!(e.contains("sensor.window_length_ps"), "{e}");
}

#[test]
fn real_picoharp_t2_replay_uses_channel_0_as_sync() {
    // Pulses = the channel-0 events; sync at 70198 Hz over 7.65 s of acquisition.
    let f = shared("picoharp_v30_t2.ptu");
    let win = TdcWindow {
        tdc_lsb_ps: 256.0,
        window_start_ps: 0.0,
        window_length_ps: 14_000_000.0,
    };
    let mut s = PulseStream::new(tttr::open(&f).unwrap(), &ReplayOptions::new(win)).unwrap();
    let pulses = s.for_each_chunk(1 << 16, |_, _| {}).unwrap();
    let c = s.counts();
    let r = s.reader().counts();
    // Every channel-0 event is a pulse; every other photon is in or outside the window or
    // before the first sync.
    assert_eq!(pulses, c.pulses);
    assert_eq!(
        r.photons,
        pulses + c.in_window + c.outside_window + c.before_first_sync
    );
    // Independently: the channel-0 events counted by a plain loop.
    let syncs = events(&f)
        .iter()
        .filter(|e| matches!(e, Event::T2Photon { channel: 0, .. }))
        .count() as u64;
    assert_eq!(pulses, syncs);
    // The header's TTResult_SyncRate (70198 Hz) is a rate meter's reading at the start;
    // the mean over the record (7.650 s from the first to the last tag, ptufile's
    // acquisition time) is 69471 Hz, 1.0% lower: 2% bounds a drifting laser, not a
    // miscounted sync (a wrong channel or wrap constant is off by far more).
    let rate = pulses as f64 / 7.650_390_672_756;
    assert!((rate - 70_198.0).abs() < 0.02 * 70_198.0, "{rate}");
}
