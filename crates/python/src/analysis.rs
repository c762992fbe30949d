//! The design's analysis calls, conversion only: the float references of a caller's frame
//! (`tofprobe_experiments::references`: the DFT at the design's bins, float ΣΔ probing,
//! the closed-form noise floor), the ΣΔ NTF the probe ROM was modulated with
//! (`tofprobe_dsp::sd::synthesize_ntf` at the probe's order, OSR, H_inf and zeros), the
//! widths and readout sizing (`tofprobe_flow::sizing::memory_input` →
//! `tofprobe_eda::memory::memory`, `tofprobe size`'s readout section) and the EDA sizing
//! report (`tofprobe_flow::sizing::size_report`), each run with the GIL released.

use numpy::Complex64;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use tofprobe_dsp::sd::ProbeRom;

use crate::Design;
use crate::convert::value_error;

/// `(frequencies_hz, amplitude_um, phase_deg)` of phasors in mm, ROM order.
pub fn phasor_tuple<'py>(
    py: Python<'py>,
    rom: &ProbeRom,
    phasors: &[Complex64],
) -> PyResult<Bound<'py, PyTuple>> {
    let a: Vec<f64> = phasors.iter().map(|y| y.norm() * 1000.0).collect();
    let p: Vec<f64> = phasors.iter().map(|y| y.arg().to_degrees()).collect();
    PyTuple::new(
        py,
        [
            rom.bins.clone().into_pyarray(py).into_any(),
            a.into_pyarray(py).into_any(),
            p.into_pyarray(py).into_any(),
        ],
    )
}

/// The float reference `which` ("dft" or "float_sd") of the frame `(valid, tdc)`.
pub fn reference<'py>(
    d: &Design,
    py: Python<'py>,
    valid: &Bound<'py, PyAny>,
    tdc: &Bound<'py, PyAny>,
    which: &str,
) -> PyResult<Bound<'py, PyTuple>> {
    let rom = d.fourier_rom(py, which)?;
    let detections = d.frame(py, valid, tdc)?;
    if detections.is_empty() {
        return Err(crate::errors::input(format!(
            "{which} of an empty frame: pass at least one pulse in `valid` and `tdc`"
        )));
    }
    let design = &d.inner;
    let phasors = py
        .detach(|| match which {
            "dft" => tofprobe_experiments::references::dft(design, rom, &detections),
            _ => tofprobe_experiments::references::float_sd(design, rom, &detections),
        })
        .map_err(value_error)?;
    phasor_tuple(py, rom, &phasors)
}

/// The closed-form noise floor (µm per bin) for a frame of `pulses`.
pub fn noise_floor<'py>(
    d: &Design,
    py: Python<'py>,
    pulses: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    let rom = d.fourier_rom(py, "noise_floor")?;
    let n = pulses.unwrap_or(d.inner.pixel.frame_pulses);
    if n == 0 {
        return Err(crate::errors::input(
            "`pulses` = 0: a frame has at least one pulse",
        ));
    }
    let design = &d.inner;
    let floor = py
        .detach(|| tofprobe_experiments::references::noise_floor_um(design, rom, n))
        .map_err(value_error)?;
    Ok(floor.into_pyarray(py).into_any())
}

/// The NTF: zeros, poles, and |NTF| on `points` frequencies 0 ..= f_s/2.
pub fn ntf<'py>(d: &Design, py: Python<'py>, points: usize) -> PyResult<Bound<'py, PyDict>> {
    if !(2..=1 << 20).contains(&points) {
        return Err(crate::errors::input(format!(
            "`points` = {points} is out of range: use 2 ..= 1048576 (e.g. 512)"
        )));
    }
    let rom = d.fourier_rom(py, "ntf")?;
    let ntf = tofprobe_dsp::sd::synthesize_ntf(rom.order, rom.osr, rom.optimised_zeros, rom.h_inf)
        .map_err(value_error)?;
    let fs = rom.sample_rate_hz;
    let (f, mag) = py.detach(|| {
        let f: Vec<f64> = (0..points)
            .map(|i| 0.5 * fs * i as f64 / (points - 1) as f64)
            .collect();
        let mag: Vec<f64> = f.iter().map(|&x| ntf.gain_at(x / fs)).collect();
        (f, mag)
    });
    let out = PyDict::new(py);
    out.set_item("order", rom.order)?;
    out.set_item("osr", rom.osr)?;
    out.set_item("h_inf", rom.h_inf)?;
    out.set_item("optimised_zeros", rom.optimised_zeros)?;
    out.set_item("zeros", ntf.zeros.clone().into_pyarray(py))?;
    out.set_item("poles", ntf.poles.clone().into_pyarray(py))?;
    out.set_item("frequencies_hz", f.into_pyarray(py))?;
    out.set_item("magnitude", mag.into_pyarray(py))?;
    Ok(out)
}

/// A serde value as Python objects (through `json.loads`).
fn to_python<'py>(py: Python<'py>, v: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).map_err(value_error)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The resolved widths and the readout sizing.
pub fn widths<'py>(d: &Design, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let design = &d.inner;
    let p = &design.pixel;
    let (input, memory) = py.detach(|| {
        let input = tofprobe_flow::sizing::memory_input(design).map_err(value_error)?;
        let m = tofprobe_eda::memory::memory(&input).map_err(value_error)?;
        Ok::<_, PyErr>((input, m))
    })?;
    let out = PyDict::new(py);
    out.set_item("width", p.width)?;
    out.set_item("tdc_bits", p.tdc_bits)?;
    out.set_item("frac_bits", p.frac_bits)?;
    out.set_item("register_frac_bits", p.register_frac_bits())?;
    out.set_item("operand_bits", p.operand_bits())?;
    out.set_item("registers", p.registers())?;
    out.set_item("frame_pulses", p.frame_pulses)?;
    out.set_item("max_abs_operand", input.max_abs_operand)?;
    out.set_item("bits_per_frame", memory.bits_per_pixel)?;
    out.set_item("readout_bits", memory.bytes_per_pixel * 8)?;
    out.set_item("memory", to_python(py, &memory)?)?;
    if let Some(chip) = &design.array {
        out.set_item(
            "array_readout_bits",
            memory.bytes_per_pixel * 8 * (chip.rows * chip.cols) as u64,
        )?;
    }
    Ok(out)
}

/// `tofprobe size`'s report as a dict; refuses, naming the tool, when yosys or OpenSTA is
/// missing.
pub fn size<'py>(
    d: &Design,
    py: Python<'py>,
    liberty: Option<std::path::PathBuf>,
    sky130: bool,
    sweep_bins: Option<Vec<u64>>,
    sweep_widths: Option<Vec<u32>>,
    node_nm: f64,
) -> PyResult<Bound<'py, PyAny>> {
    use tofprobe_eda::tools::Tool;
    for tool in [Tool::Yosys, Tool::Sta] {
        tool.locate().map_err(|e| {
            crate::errors::tool_missing(format!("Design.size needs the EDA tools: {e}"))
        })?;
    }
    let options = tofprobe_flow::sizing::SizeOptions {
        liberty,
        no_sky130: !sky130,
        sky130_pdk: None,
        node_nm,
        sweep_bins,
        sweep_widths,
        cache: None,
        corner_trials: tofprobe_flow::sizing::DEFAULT_CORNER_TRIALS,
    };
    // Minutes of syntheses with no chunk to stop between: Ctrl-C returns at once and the
    // abandoned run finishes in the background (its cache entries are written atomically).
    let design = d.inner.clone();
    let report = crate::long_call::detached(py, move || {
        tofprobe_flow::sizing::size_report(&design, &options)
    })?
    .map_err(value_error)?;
    to_python(py, &report)
}
