//! Quick speed check of both fidelities at the default B = 16 (`tofprobe bench pixel` is
//! the user-facing version): `cargo run --release -p tofprobe-pixel --example pixel_speed`.

use tofprobe_pixel::PixelParams;
use tofprobe_pixel::bench::{bench_cycle, bench_transaction, synthetic_rom};

fn main() {
    let n = 10_000_000;
    let p = PixelParams::fourier_default(40, n as u64, 4096);
    let rom = synthetic_rom(4096, 32);
    match bench_transaction(&p, n, &rom, 10e6) {
        Ok(t) => println!("{t:?}"),
        Err(e) => eprintln!("{e}"),
    }
    let mut pc = p.clone();
    pc.frame_pulses = 100_000;
    match bench_cycle(&pc, &rom, 1) {
        Ok(c) => println!("{c:?}"),
        Err(e) => eprintln!("{e}"),
    }
}
