//! Per-pixel determinism: pixel (r, c)'s registers depend only on (seed, r, c). Tiles run
//! separately — on pools of 1 and 2 threads, from a design sent through JSON as a worker
//! process receives it, their results sent back through JSON — merge into the whole
//! array's frame byte for byte; every pixel equals the single-pixel transaction model
//! driven pulse by pulse on that pixel's stream (the naive reference, Fourier and Haar).

use tofprobe_array::model::{merge, run_array, run_tile};
use tofprobe_design::ResolvedDesign;
use tofprobe_pixel::transaction::TransactionModel;

use crate::common::{design, haar_design, plate};

const ARRAY: &str = "rows = 5\ncols = 4\npitch_um = 30.0\nmm_per_pixel = 20.0\n\
                     signal_map = { kind = \"gradient\", from = 0.3, to = 1.0 }\n\
                     background_map = { kind = \"constant\", value = 0.05 }";

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

#[test]
fn tiles_on_any_pool_and_process_merge_into_the_array() {
    tiles_merge(&design(&plate(2, 1), 40_000, ARRAY));
}

/// The same at `level = "auto"` on a plate over the right half (x ≥ 40 mm of the 80 mm
/// wide array): its static pixels drawn, its moving ones bit-true, the map decided in
/// each worker from the design it received.
#[test]
fn auto_tiles_on_any_pool_and_process_merge_into_the_array() {
    let arr = format!("{ARRAY}\nlevel = \"auto\"");
    let d = design(&crate::auto::half_plate(40.0, 40.0, 100.0), 40_000, &arr);
    let map = tofprobe_array::statistical::auto::level_map(&d).unwrap();
    assert!(map.iter().any(|l| l.is_bit_true()) && !map.iter().all(|l| l.is_bit_true()));
    tiles_merge(&d);
}

fn tiles_merge(d: &ResolvedDesign) {
    let d = d.clone();
    let rom = d.probe_rom().unwrap().unwrap();
    let whole = pool(2).install(|| run_array(&d, Some(&rom.image))).unwrap();
    // A worker gets the design as JSON, runs its tile and returns it as JSON.
    let worker = |rows: std::ops::Range<usize>, cols: std::ops::Range<usize>, threads| {
        let received = ResolvedDesign::from_json(&d.to_json().unwrap()).unwrap();
        let rom = received.probe_rom().unwrap().unwrap();
        let tile = pool(threads)
            .install(|| run_tile(&received, Some(&rom.image), rows, cols))
            .unwrap();
        serde_json::from_str(&serde_json::to_string(&tile).unwrap()).unwrap()
    };
    let tiles = vec![
        worker(0..2, 0..4, 1),
        worker(2..5, 0..1, 2),
        worker(2..5, 1..4, 1),
    ];
    let merged = merge(5, 4, &tiles).unwrap();
    assert_eq!(merged, whole, "the tiled array equals the whole");
    // Pixels differ from each other (distinct seeds and rates), so the test can fail.
    assert_ne!(whole.pixel(0, 0), whole.pixel(0, 1));
    // A gap or an overlap is refused, naming the pixel.
    let e = merge(5, 4, &tiles[..2]).unwrap_err().to_string();
    assert!(e.contains("(2, 1) is in no tile"), "{e}");
    let e = merge(5, 4, &[tiles[0].clone(), tiles[0].clone()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("(0, 0) is in two tiles"), "{e}");
}

/// The naive reference: the single-pixel model, one `pulse` call per pulse of the pixel's
/// own record, ROM address n mod L.
fn reference(d: &ResolvedDesign, r: usize, c: usize) -> Vec<i64> {
    let src = d.pixel_source(r, c).unwrap();
    let rom = d.probe_rom().unwrap();
    let mut tm = TransactionModel::new(&d.pixel).unwrap();
    for (n, det) in src.record(d.pixel.frame_pulses).into_iter().enumerate() {
        let entry = match &rom {
            Some(rom) => rom.image.entry(n % d.pixel.rom_depth).to_vec(),
            None => Vec::new(),
        };
        tm.pulse(det, &entry);
    }
    tm.readout().words
}

#[test]
fn every_sampled_pixel_is_the_single_pixel_model_on_its_stream() {
    let d = design(&plate(1, 2), 40_000, ARRAY);
    let rom = d.probe_rom().unwrap().unwrap();
    let frame = run_array(&d, Some(&rom.image)).unwrap();
    for (r, c) in [(0, 0), (2, 3), (4, 1)] {
        assert_eq!(frame.pixel(r, c), reference(&d, r, c), "pixel ({r}, {c})");
    }
    // Haar: a step sweeping the array, 2^15 pulses, U = 4.
    let edge = "[[scene.motion]]\nkind = \"edge\"\nheight_mm = -4.0\nvelocity_mm_per_s = 20000.0\n";
    let d = haar_design(edge, 1 << 15, ARRAY);
    let frame = run_array(&d, None).unwrap();
    assert_eq!(frame.registers_per_pixel, 31);
    for (r, c) in [(0, 0), (3, 2)] {
        assert_eq!(
            frame.pixel(r, c),
            reference(&d, r, c),
            "Haar pixel ({r}, {c})"
        );
    }
}

/// A lane group (the pixels of the array run in lockstep by the pixel's lane driver) gives
/// each pixel the registers and detections it has alone, whichever pixels share the group
/// and in which order.
#[test]
fn a_lane_group_is_each_pixel_alone() {
    use tofprobe_array::model::{run_group, run_pixel};
    let d = design(&plate(1, 2), 40_000, ARRAY);
    let rom = d.probe_rom().unwrap().unwrap();
    let group = [(4, 3), (0, 0), (2, 1)];
    let lanes = run_group(&d, &rom.image, &group).unwrap();
    for (&(r, c), got) in group.iter().zip(&lanes) {
        assert_eq!(
            got,
            &run_pixel(&d, Some(&rom.image), r, c).unwrap(),
            "({r}, {c})"
        );
    }
    let alone = run_group(&d, &rom.image, &group[1..2]).unwrap();
    assert_eq!(alone[0], lanes[1]);
    assert_ne!(lanes[0], lanes[1], "pixels differ, so the test can fail");
}

/// Every ISA path of the vector kernels this CPU runs (`tofprobe_io::isa`: the Monte
/// Carlo's batch, the pixels' lanes) gives the scalar path's array registers and detection
/// counts, byte for byte; a path the CPU lacks is skipped with a note. The pixels differ
/// from each other, so a wrong lane would show.
#[test]
fn every_isa_gives_the_scalar_array() {
    use tofprobe_io::isa::{Isa, with_isa};
    let d = design(&plate(2, 1), 40_000, ARRAY);
    let rom = d.probe_rom().unwrap().unwrap();
    let run = |isa| with_isa(isa, || pool(2).install(|| run_array(&d, Some(&rom.image))));
    let scalar = run(Isa::Scalar).unwrap();
    assert_ne!(scalar.pixel(0, 0), scalar.pixel(4, 3));
    for isa in Isa::vector_paths_to_test() {
        assert_eq!(run(isa).unwrap(), scalar, "{}", isa.name());
    }
}
