//! Renders a configuration (a `[pixel]` TOML table of explicit parameters, or the default)
//! into a directory: a developer aid.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = std::path::PathBuf::from(args.next().unwrap_or_else(|| "out".into()));
    let p = match args.next() {
        Some(f) => {
            let text = std::fs::read_to_string(&f)?;
            let p: tofprobe_pixel::PixelParams = toml::from_str(&text)?;
            p
        }
        None => tofprobe_pixel::PixelParams::default(),
    };
    let rom = tofprobe_rtlgen::stimulus::sign_probe_rom(&p);
    let files = tofprobe_rtlgen::render(&p, &rom, &Default::default())?;
    let pairs: Vec<(String, String)> = files.into_iter().map(|f| (f.name, f.contents)).collect();
    tofprobe_rtlgen::write::write_generated(&out, &pairs)?;
    Ok(())
}
