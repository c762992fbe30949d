//! The technologies the pixel is laid out in, as qflow technology directories.
//!
//! osu018 is qflow's own (Debian's `qflow-tech-osu018`: liberty, cell LEF, SPICE, magic
//! technology, graywolf parameters, netgen setup; no cell GDS, so magic's GDS holds the
//! cells' LEF abstracts). sky130 is assembled from the PDK directory (the vendored
//! third_party/sky130_fd_sc_hd by default, the same public source as the liberties,
//! `tofprobe_eda::pdk`): its technology LEF, merged cell
//! LEF, cell GDS, CDL, magic technology file and netgen setup, decompressed into the cache,
//! with a qflow setup script, graywolf parameters and a magic startup file written here.

use crate::error::{LayoutError, Result};
use std::path::{Path, PathBuf};

/// qflow's technologies directory (Debian).
pub const QFLOW_TECH: &str = "/usr/share/qflow/tech";

/// A technology to lay out in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tech {
    /// OSU 0.18 µm (qflow's own; the route that always works).
    Osu018,
    /// SkyWater 130 nm, sky130_fd_sc_hd.
    Sky130,
}

impl Tech {
    /// The name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Tech::Osu018 => "osu018",
            Tech::Sky130 => "sky130",
        }
    }

    /// The node (nm) its area scales from.
    pub fn node_nm(self) -> f64 {
        match self {
            Tech::Osu018 => 180.0,
            Tech::Sky130 => 130.0,
        }
    }

    /// Parses `osu018` / `sky130`.
    pub fn parse(s: &str) -> Result<Tech> {
        match s {
            "osu018" => Ok(Tech::Osu018),
            "sky130" => Ok(Tech::Sky130),
            _ => Err(LayoutError::Option {
                option: "tech",
                value: s.to_string(),
                allowed: "osu018 or sky130 (osu018 always routes)".into(),
            }),
        }
    }
}

/// A technology ready for qflow.
#[derive(Debug, Clone, PartialEq)]
pub struct TechFiles {
    /// Which technology.
    pub tech: Tech,
    /// qflow's `techdir`.
    pub dir: PathBuf,
    /// qflow's `techname` (`DIR/NAME.sh` is its setup script).
    pub name: String,
    /// The liberty synthesis maps onto and STA reads (typical corner).
    pub liberty: PathBuf,
    /// The cell LEF.
    pub cell_lef: PathBuf,
    /// The technology LEF (routing layers' widths, vias): osu018's is its cell LEF.
    pub tech_lef: PathBuf,
    /// The fill cell.
    pub fill: String,
    /// The buffer (cell, input pin, output pin) the BLIF conversion drives ports with.
    pub buffer: (&'static str, &'static str, &'static str),
}

impl TechFiles {
    /// osu018 from Debian's qflow-tech-osu018.
    pub fn osu018() -> Result<TechFiles> {
        let dir = Path::new(QFLOW_TECH).join("osu018");
        let t = TechFiles {
            tech: Tech::Osu018,
            liberty: dir.join("osu018_stdcells.lib"),
            cell_lef: dir.join("osu018_stdcells.lef"),
            tech_lef: dir.join("osu018_stdcells.lef"),
            dir,
            name: "osu018".into(),
            fill: "FILL".into(),
            buffer: ("BUFX2", "A", "Y"),
        };
        for (what, p) in [
            ("liberty", &t.liberty),
            ("cell LEF", &t.cell_lef),
            ("qflow setup", &t.dir.join("osu018.sh")),
        ] {
            if !p.is_file() {
                return Err(LayoutError::TechFile {
                    tech: "osu018",
                    what,
                    path: p.clone(),
                    hint: "Debian's qflow-tech-osu018 (scripts/install-tools.sh)",
                });
            }
        }
        Ok(t)
    }

    /// sky130 from the PDK directory `pdk` (by default the vendored
    /// third_party/sky130_fd_sc_hd, see [`tofprobe_eda::pdk`]), assembled under
    /// `cache/layout-tech/sky130`.
    pub fn sky130(pdk: &Path, cache: &Path) -> Result<TechFiles> {
        let plain = |stem: &str| -> Result<PathBuf> {
            let found = [pdk.join(stem), pdk.join(format!("{stem}.gz"))]
                .into_iter()
                .find(|p| p.is_file())
                .ok_or_else(|| LayoutError::TechFile {
                    tech: "sky130",
                    what: "a PDK file",
                    path: pdk.join(stem),
                    hint: "the vendored third_party/sky130_fd_sc_hd (see its README.md), --sky130-pdk DIR or $TOFPROBE_SKY130_PDK",
                })?;
            Ok(tofprobe_eda::pdk::plain_copy(&found, cache)?)
        };
        let liberty = plain("sky130_fd_sc_hd__tt_025C_1v80.lib")?;
        let cell_lef = plain("sky130_fd_sc_hd_merged.lef")?;
        let tlef = plain("sky130_fd_sc.tlef")?;
        let gds = plain("sky130_fd_sc_hd.gds")?;
        let cdl = plain("sky130_fd_sc_hd.cdl")?;
        let magic_tech = plain("sky130A.tech")?;
        let netgen = plain("lvs_setup.tcl")?;
        let dir = cache.join("layout-tech").join("sky130");
        std::fs::create_dir_all(&dir).map_err(|e| LayoutError::io("creating", &dir, e))?;
        let write = |name: &str, text: String| -> Result<()> {
            let p = dir.join(name);
            tofprobe_io::write_atomic(&p, text.as_bytes())
                .map_err(|e| LayoutError::io("writing", &p, e))
        };
        write(
            "sky130.sh",
            sky130_setup(&cell_lef, &tlef, &cdl, &liberty, &gds, &netgen),
        )?;
        write("sky130.par", SKY130_PAR.to_string())?;
        write(
            "sky130.magicrc",
            format!(
                "tech load {} -noprompt\nset GND VGND\nset VDD VPWR\ndrc euclidean on\ndrc off\n",
                magic_tech.display()
            ),
        )?;
        Ok(TechFiles {
            tech: Tech::Sky130,
            dir,
            name: "sky130".into(),
            liberty,
            cell_lef,
            tech_lef: tlef,
            fill: "sky130_fd_sc_hd__fill_1".into(),
            buffer: ("sky130_fd_sc_hd__buf_1", "A", "X"),
        })
    }
}

/// qflow's setup script for sky130_fd_sc_hd (the variables osu018.sh sets).
fn sky130_setup(
    lef: &Path,
    tlef: &Path,
    cdl: &Path,
    lib: &Path,
    gds: &Path,
    netgen: &Path,
) -> String {
    format!(
        "#!/usr/bin/tcsh\n# Written by tofprobe layout: qflow setup for sky130_fd_sc_hd.\n\
set leffile={lef}\nset techleffile={tlef}\nset spicefile={cdl}\nset libertyfile={lib}\n\
set gdsfile={gds}\nset netgen_setup={netgen}\n\
set flopcell=sky130_fd_sc_hd__dfxtp_1\nset floppinout=Q\nset floppinin=D\nset floppinclk=CLK\n\
set bufcell=sky130_fd_sc_hd__buf_1\nset bufpin_in=A\nset bufpin_out=X\n\
set clkbufcell=sky130_fd_sc_hd__clkbuf_1\nset clkbufpin_in=A\nset clkbufpin_out=X\n\
set inverter=sky130_fd_sc_hd__inv_1\nset invertpin_in=A\nset invertpin_out=Y\n\
set norgate=sky130_fd_sc_hd__nor2_1\nset norpin_in1=A\nset norpin_in2=B\nset norpin_out=Y\n\
set nandgate=sky130_fd_sc_hd__nand2_1\nset nandpin_in1=A\nset nandpin_in2=B\nset nandpin_out=Y\n\
set fillcell=sky130_fd_sc_hd__fill_1\nset decapcell=\"\"\nset antennacell=\"\"\nset antennapin_in=\"\"\n\
set tiehi=\"sky130_fd_sc_hd__conb_1\"\nset tiehipin_out=\"HI\"\nset tielo=\"sky130_fd_sc_hd__conb_1\"\nset tielopin_out=\"LO\"\n\
set separator=\"\"\nset techfile=sky130A\nset magicrc=sky130.magicrc\n\
set fanout_options=\"-l 100 -c 20\"\nset via_stacks=\"2\"\n\
set addspacers_options=\"-stripe 1.6 50.0 PG\"\n\
set xspice_options=\"-io_time=1n -time=100p -idelay=10p -odelay=100p -cload=500f\"\n",
        lef = lef.display(),
        tlef = tlef.display(),
        cdl = cdl.display(),
        lib = lib.display(),
        gds = gds.display(),
        netgen = netgen.display(),
    )
}

/// graywolf's parameters for sky130_fd_sc_hd (centimicrons): the routing layers of the
/// technology LEF (li1 is the cells' own layer; met1–met4 route), pitches as track pitch −
/// width, as qflow's osu018.par states them.
const SKY130_PAR: &str = "RULES
    layer met1 0.125 0.036 horizontal
    layer met2 0.125 0.016 vertical
    layer met3 0.047 0.008 horizontal
    layer met4 0.047 0.005 vertical
    via via met1 met2
    via via2 met2 met3
    via via3 met3 met4
    width met1 14
    width met2 14
    width met3 30
    width met4 30
    width via 15
    width via2 20
    width via3 20
    spacing met1 met1 20
    spacing met2 met2 32
    spacing met3 met3 38
    spacing met4 met4 62
    spacing via via2 0
    spacing via2 via3 0
    overhang via met1 6
    overhang via met2 8
    overhang via2 met2 4
    overhang via2 met3 6
    overhang via3 met3 6
    overhang via3 met4 6
ENDRULES

*vertical_wire_weight : 1.0
*vertical_path_weight : 1.0
*padspacing           : variable
*rowSep               : 0.0   0
*track.pitch          : 46
*minimum_pad_space    : 92
*gridX                : 46
*gridY                : 34
*gridOffsetX          : 0
*gridOffsetY          : 0
*graphics.wait        : off
*last_chance.wait     : off
*random.seed          : 12345

TWMC*chip.aspect.ratio : 0.75

TWSC*feedThruWidth    : 46 layer 1
TWSC*do.global.route  : on
TWSC*ignore_feeds     : true
TWSC*call_row_evener  : true
TWSC*even_rows_maximally : true

GENR*row_to_tile_spacing : 1
GENR*flip_alternate_rows : 1
";
