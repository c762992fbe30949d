//! What a time-tagged record may ask of a replay, checked before a pulse is streamed: the
//! laser pulses it spans, its delay resolution and its sync rate. A replay streams every
//! pulse of the record (the pixel accumulates its held depth on empty pulses too), so its
//! cost is the pulses the records' sync counts imply, not the file's size: one B&H
//! "multiple macro-time overflow" record can claim 2^28 − 1 overflows (≈ 1.1·10^12 pulses,
//! a day of CPU from a 16-byte file) and each all-ones HydraHarp T3 record ≈ 10^6.
//!
//! [`check_span`] reads the records once, counting each record's pulses from the sync
//! counts it carries (arithmetic, no pulse iterated: the cost is the file's size), and
//! refuses the first record that takes the record beyond [`MAX_RECORD_PULSES`], naming it.
//! [`resolution_s`] and [`sync_rate_hz`] refuse physically absurd header values (or
//! options) naming the header tag they came from, not a sensor key the user never wrote.

use std::path::Path;

use tofprobe_scene::SceneError;
use tofprobe_scene::tttr::{self, Event, RecordFormat, TttrHeader};

use crate::error::ExperimentError;

/// Most laser pulses a replayed record may span: 2^32 (7.2 min at 10 MHz, 54 s at 80 MHz).
/// The replay streams each pulse (≈ 0.5 ns per pulse per pass, two passes) and runs the
/// fitted frame, the whole record, through the pixel model (≈ 40 ns per pulse): about
/// three minutes at the cap. Longer acquisitions are replayed in pieces.
pub const MAX_RECORD_PULSES: u64 = 1 << 32;

/// Finest delay bin (T3) or time-tag unit (T2) accepted: 1 fs. The finest TCSPC bins are
/// ≈ 1 ps; the replay rounds bins to 10^-6 ps, so 10^-20 s became a bin of 0 ps and every
/// photon fell in code 0 (σ 0, every amplitude 0, exit 0).
pub const MIN_RESOLUTION_S: f64 = 1e-15;

/// Coarsest delay bin or time-tag unit accepted (exclusive): 1 s, the replay's own bound.
pub const MAX_RESOLUTION_S: f64 = 1.0;

/// Slowest sync (laser) rate a record is fitted at: 1 kHz, a sync period of at most 1 ms,
/// the longest timing window a sensor takes (`sensor.window_length_ps` ≤ 10^9 ps).
pub const MIN_SYNC_RATE_HZ: f64 = 1e3;

/// Fastest sync rate: 10 GHz, as `sensor.laser_rate_hz`.
pub const MAX_SYNC_RATE_HZ: f64 = 1e10;

/// Reads every record of `path` once and returns the pulses it spans (T3/SPC: the last
/// overflow-corrected sync count + 1; T2: the sync records are the pulses, bounded by the
/// file's size, so 0 is returned unchecked). Refuses the first record past
/// [`MAX_RECORD_PULSES`], naming its index and byte, what it claims and the cap.
pub fn check_span(path: &Path) -> Result<u64, ExperimentError> {
    let mut r = tttr::open(path)?;
    if !r.header().format.is_t3() {
        return Ok(0);
    }
    while let Some(ev) = r.next_event()? {
        let pulses = r.last_time().saturating_add(1);
        if pulses <= MAX_RECORD_PULSES {
            continue;
        }
        let what = match ev {
            Event::Overflow { wraps } => {
                format!("an overflow record of {wraps} wrap-around(s) of the sync count")
            }
            Event::T3Photon { sync, .. } => format!("a photon at sync count {sync}"),
            Event::Marker { time, .. } => format!("a marker at sync count {time}"),
            _ => "a record".to_string(),
        };
        return Err(SceneError::Tttr {
            file: r.file().to_string(),
            at: r.at(r.record_index() - 1),
            expected: format!(
                "a record spanning at most {MAX_RECORD_PULSES} laser pulses (2^32, the \
                 replay's cap: every pulse is streamed through the pixel); replay the \
                 records before this one"
            ),
            found: format!("{what}, which takes the record to {pulses} pulses"),
        }
        .into());
    }
    Ok(r.last_time() + 1)
}

/// The delay bin (T3) or time-tag unit (T2) the replay uses, in seconds: `--resolution-s`
/// when given, else the header's; refused outside [[`MIN_RESOLUTION_S`],
/// [`MAX_RESOLUTION_S`]) naming the option or the header tag it came from. `None` when
/// neither gives one (SPC without `--resolution-s`: the replay says what to pass).
pub fn resolution_s(
    path: &Path,
    header: &TttrHeader,
    option: Option<f64>,
) -> Result<Option<f64>, ExperimentError> {
    let allowed = format!(
        "{MIN_RESOLUTION_S:e} <= s < {MAX_RESOLUTION_S} (seconds per delay bin or time-tag \
         unit; TCSPC bins are ≈ 1 ps and up)"
    );
    let fits = |s: f64| s.is_finite() && (MIN_RESOLUTION_S..MAX_RESOLUTION_S).contains(&s);
    if let Some(s) = option {
        if !fits(s) {
            return Err(ExperimentError::option(
                "resolution-s",
                tofprobe_io::text::number(s),
                &allowed,
            ));
        }
        return Ok(Some(s));
    }
    match header.resolution_s {
        Some(s) if !fits(s) => Err(SceneError::Tttr {
            file: path.display().to_string(),
            at: format!("header tag `{}`", resolution_tag(header.format)),
            expected: format!("{allowed}; or give --resolution-s"),
            found: tofprobe_io::text::number(s),
        }
        .into()),
        s => Ok(s),
    }
}

/// The PTU tag the resolution comes from.
fn resolution_tag(f: RecordFormat) -> &'static str {
    if f.is_t3() {
        "MeasDesc_Resolution"
    } else {
        "MeasDesc_GlobalResolution"
    }
}

/// The sync (laser) rate a record is fitted at: `TTResult_SyncRate`, else the inverse of
/// `MeasDesc_GlobalResolution` (SPC: of the macro-time clock in its first word); refused
/// outside [[`MIN_SYNC_RATE_HZ`], [`MAX_SYNC_RATE_HZ`]] naming that tag (it used to be
/// blamed on `sensor.tdc_lsb_ps`, a key the user never wrote).
pub fn sync_rate_hz(path: &Path, header: &TttrHeader) -> Result<f64, ExperimentError> {
    let (rate, tag) = match (header.sync_rate_hz, header.global_resolution_s) {
        (Some(r), _) => (r, "header tag `TTResult_SyncRate`"),
        (None, Some(g)) if header.format == RecordFormat::BeckerHicklSpc => {
            (1.0 / g, "byte 0 (SPC header: the macro-time clock)")
        }
        (None, Some(g)) => (1.0 / g, "header tag `MeasDesc_GlobalResolution`"),
        (None, None) => {
            return Err(ExperimentError::option(
                "CONFIG",
                path.display(),
                "a record whose header gives the sync rate, or a configuration",
            ));
        }
    };
    if rate.is_finite() && (MIN_SYNC_RATE_HZ..=MAX_SYNC_RATE_HZ).contains(&rate) {
        return Ok(rate);
    }
    Err(SceneError::Tttr {
        file: path.display().to_string(),
        at: tag.to_string(),
        expected: format!(
            "a sync (laser) rate of {MIN_SYNC_RATE_HZ} to {MAX_SYNC_RATE_HZ:e} Hz to fit the \
             sensor to (a period of at most 1 ms); or replay with a configuration"
        ),
        found: format!("{} Hz", tofprobe_io::text::number(rate)),
    }
    .into())
}
