//! `tofprobe cosim --junit FILE` as CI runs it (issue 21): a passing run's report is
//! well-formed XML with one test case per frame and no failure; a hand-broken pixel gives
//! exactly one failure, on the frame of the first mismatch, naming its cycle and signal as
//! the JSON verdict of the same run does; a configuration name full of markup and a newline
//! is escaped; a foreign file is refused before simulating. Icarus on the committed short
//! RTL (N = 64): a few seconds per run.

use crate::common;
use common::{default_text, tofprobe};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn tools() -> bool {
    common::have_tools(&["iverilog", "vvp"])
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("junit")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("mkdir");
    d
}

/// A copy of testbench/default-short/rtl (the default with N = 64).
fn copy_short(to: &Path) -> PathBuf {
    let from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testbench/default-short/rtl");
    let to = to.join("rtl");
    std::fs::create_dir_all(&to).expect("mkdir");
    for e in std::fs::read_dir(&from).expect("dir") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), to.join(e.file_name())).expect("copy");
    }
    to
}

/// Adder 0 subtracts where it should add (an ECO gone wrong).
fn break_pixel(rtl: &Path) {
    let pixel = rtl.join("tofprobe_pixel.v");
    let text = std::fs::read_to_string(&pixel).expect("pixel");
    let good = "add_0 ? (yin_0 + opx) : (yin_0 - opx)";
    assert!(text.contains(good), "the pixel's adder 0 line moved");
    std::fs::write(
        &pixel,
        text.replace(good, "add_0 ? (yin_0 - opx) : (yin_0 + opx)"),
    )
    .expect("write");
}

/// An element as the checker saw it: name and attributes (values unescaped).
#[derive(Debug, Clone)]
struct Element {
    name: String,
    attrs: BTreeMap<String, String>,
    /// Its text content up to the first child (unescaped).
    text: String,
}

fn unescape(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        let end = rest[i..].find(';').expect("entity ends with ;") + i;
        let ent = &rest[i + 1..end];
        let c = match ent {
            "amp" => '&',
            "lt" => '<',
            "gt" => '>',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let n = ent
                    .strip_prefix('#')
                    .expect("known entity or character reference");
                char::from_u32(n.parse().expect("decimal reference")).expect("valid char")
            }
        };
        out.push(c);
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    out
}

/// A strict little XML well-formedness check (what the report uses of XML: declaration,
/// comments, elements with quoted attributes, character data, the five entities and
/// decimal character references): every tag balanced, no raw `<` or stray `&` in text or
/// values, one root. Returns the elements in document order.
fn parse(xml: &str) -> Vec<Element> {
    let mut rest = xml
        .strip_prefix("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n")
        .expect("XML declaration first");
    let mut stack: Vec<String> = Vec::new();
    let mut out: Vec<Element> = Vec::new();
    let mut roots = 0;
    while !rest.is_empty() {
        let lt = rest.find('<').unwrap_or(rest.len());
        let text = &rest[..lt];
        assert!(
            stack.is_empty() == text.trim().is_empty() || !stack.is_empty(),
            "text outside the root: {text:?}"
        );
        let t = unescape(text);
        if let (Some(last), false) = (out.last_mut(), text.trim().is_empty()) {
            last.text.push_str(&t);
        }
        rest = &rest[lt..];
        if rest.is_empty() {
            break;
        }
        if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").expect("comment closed");
            assert!(!r[..end].contains("--"), "`--` inside a comment");
            rest = &r[end + 3..];
            continue;
        }
        let gt = rest.find('>').expect("tag closed");
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name), "unbalanced </{name}>");
            continue;
        }
        let (body, empty) = match tag.strip_suffix('/') {
            Some(b) => (b, true),
            None => (tag, false),
        };
        let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
        let name = body[..name_end].to_string();
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric()),
            "bad tag name {name:?}"
        );
        let mut attrs = BTreeMap::new();
        let mut a = body[name_end..].trim_start();
        while !a.is_empty() {
            let eq = a.find("=\"").expect("attribute is name=\"value\"");
            let key = a[..eq].to_string();
            let v = &a[eq + 2..];
            let close = v.find('"').expect("attribute value closed");
            let raw = &v[..close];
            assert!(!raw.contains('<'), "raw < in attribute {key}");
            assert!(
                !raw.contains('\n'),
                "raw newline in attribute {key} (it would be normalised away)"
            );
            assert!(
                attrs.insert(key.clone(), unescape(raw)).is_none(),
                "duplicate attribute {key}"
            );
            a = v[close + 1..].trim_start();
        }
        if stack.is_empty() {
            roots += 1;
        }
        out.push(Element {
            name: name.clone(),
            attrs,
            text: String::new(),
        });
        if !empty {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    assert_eq!(roots, 1, "one root element");
    out
}

fn count(els: &[Element], name: &str) -> usize {
    els.iter().filter(|e| e.name == name).count()
}

fn cosim(rtl: &Path, out: &Path, junit: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "cosim".to_string(),
        "--rtl".into(),
        rtl.display().to_string(),
        "--frame-pulses".into(),
        "64".into(),
        "--frames".into(),
        "3".into(),
        "--simulator".into(),
        "icarus".into(),
        // The report only: no traced Verilator build for a VCD of a mismatch.
        "--no-vcd".into(),
        "--json".into(),
        "--out".into(),
        out.join("work").display().to_string(),
        "--junit".into(),
        junit.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    tofprobe(&refs)
}

fn json(o: &std::process::Output) -> serde_json::Value {
    common::last_json(o)
}

#[test]
fn passing_run_has_one_case_per_frame_and_no_failure() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("pass");
    let rtl = copy_short(&d);
    let file = d.join("report.xml");
    let o = cosim(&rtl, &d, &file, &[]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let xml = std::fs::read_to_string(&file).expect("report written");
    let els = parse(&xml);
    assert_eq!(count(&els, "testsuites"), 1);
    assert_eq!(count(&els, "testsuite"), 1);
    assert_eq!(count(&els, "testcase"), 3, "one case per frame:\n{xml}");
    assert_eq!(count(&els, "failure"), 0);
    assert_eq!(count(&els, "skipped"), 0);
    let root = &els[0];
    assert_eq!(root.attrs["tests"], "3");
    assert_eq!(root.attrs["failures"], "0");
    // The hash the RTL's header names (cosim checked it against the configuration).
    let top = std::fs::read_to_string(rtl.join("tofprobe_top.v")).expect("top");
    let hash = top
        .split("Configuration hash: ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .expect("hash in the header");
    let cases: Vec<&Element> = els.iter().filter(|e| e.name == "testcase").collect();
    for (k, c) in cases.iter().enumerate() {
        assert_eq!(c.attrs["name"], format!("frame {k}"));
        assert_eq!(c.attrs["classname"], format!("default.{hash}"));
    }
    // The file is the generator's: a second run replaces it.
    let o = cosim(&rtl, &d, &file, &[]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
}

#[test]
fn broken_pixel_fails_on_the_frame_of_its_first_mismatch() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("broken");
    let rtl = copy_short(&d);
    break_pixel(&rtl);
    let file = d.join("report.xml");
    let o = cosim(&rtl, &d, &file, &[]);
    assert_eq!(o.status.code(), Some(1), "FAIL exits 1: {o:?}");
    let j = json(&o);
    let xml = std::fs::read_to_string(&file).expect("report written on FAIL too");
    let els = parse(&xml);
    assert_eq!(count(&els, "testcase"), 3);
    assert_eq!(count(&els, "failure"), 1, "{xml}");
    let fi = els
        .iter()
        .position(|e| e.name == "failure")
        .expect("failure");
    let f = &els[fi];
    let cycle = j["first_mismatch_cycle"].as_u64().expect("cycle");
    let signal = j["first_mismatch_signal"].as_str().expect("signal");
    let msg = &f.attrs["message"];
    assert!(
        msg.contains(&format!("cycle {cycle} "))
            && msg.contains(signal)
            && msg.contains(&format!(
                "expected {}",
                j["first_mismatch_expected"].as_str().expect("expected")
            ))
            && msg.contains(&format!(
                "actual {}",
                j["first_mismatch_actual"].as_str().expect("actual")
            )),
        "failure message {msg:?} vs JSON {j}"
    );
    // Frame 0's readout ends after 64 pulses × 16 cycles: a mismatch before it is frame 0's.
    assert!(cycle < 64 * 16, "adder 0's first wrong write is early");
    assert_eq!(els[fi - 1].attrs["name"], "frame 0");
    assert_eq!(count(&els, "skipped"), 2, "later frames are not judged");
    assert_eq!(els[0].attrs["failures"], "1");
}

#[test]
fn configuration_name_is_escaped_and_foreign_files_refused() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("escape");
    let rtl = copy_short(&d);
    let name = "a<b>&\"c'\nd";
    let config = d.join(format!("{name}.toml"));
    std::fs::write(&config, default_text()).expect("config");
    let file = d.join("report.xml");
    let o = cosim(&rtl, &d, &file, &[config.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let xml = std::fs::read_to_string(&file).expect("report");
    let els = parse(&xml);
    let case = els.iter().find(|e| e.name == "testcase").expect("case");
    assert!(
        case.attrs["classname"].starts_with(name),
        "the name survives escaping: {:?}",
        case.attrs["classname"]
    );
    assert!(xml.contains("a&lt;b&gt;&amp;&quot;c&apos;&#10;d."), "{xml}");
    // The command property is one sanitised line.
    let cmd = els
        .iter()
        .find(|e| e.name == "property" && e.attrs["name"] == "command")
        .expect("command property");
    assert!(!cmd.attrs["value"].contains(['\n', '<', '"']));

    // A file tofprobe did not write is refused before any simulation, and left alone.
    let foreign = d.join("foreign.xml");
    std::fs::write(&foreign, "<mine/>\n").expect("write");
    let o = cosim(&rtl, &d, &foreign, &[]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("refusing to overwrite"), "{err}");
    assert!(o.stdout.is_empty(), "refused before simulating");
    assert_eq!(
        std::fs::read_to_string(&foreign).expect("kept"),
        "<mine/>\n"
    );
}

/// Whether `c` is in XML 1.0's `Char` production (#x9 | #xA | #xD | [#x20-#xD7FF] |
/// [#xE000-#xFFFD] | [#x10000-#x10FFFF]).
fn xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{d7ff}' | '\u{e000}'..='\u{fffd}')
        || c >= '\u{10000}'
}

/// A configuration named with characters XML 1.0 does not allow (the noncharacters U+FFFE
/// and U+FFFF, a C0 control) gives a report every character of which is XML (U+FFFE went
/// into the file raw, and XML parsers refused it), the name's other characters kept.
#[test]
fn configuration_name_with_xml_invalid_characters_is_replaced() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("noncharacters");
    let rtl = copy_short(&d);
    let name = "cfg\u{fffe}x\u{ffff}y\u{1b}z";
    let config = d.join(format!("{name}.toml"));
    std::fs::write(&config, default_text()).expect("config");
    let file = d.join("report.xml");
    let o = cosim(&rtl, &d, &file, &[config.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let xml = std::fs::read_to_string(&file).expect("report");
    let bad: Vec<char> = xml.chars().filter(|c| !xml_char(*c)).collect();
    assert!(bad.is_empty(), "characters outside XML 1.0: {bad:?}");
    let els = parse(&xml);
    let case = els.iter().find(|e| e.name == "testcase").expect("case");
    assert!(
        case.attrs["classname"].starts_with("cfg\u{fffd}x\u{fffd}y\u{fffd}z."),
        "{:?}",
        case.attrs["classname"]
    );
}

/// The checker above can fail: crossed tags, a raw `<` in a value, an unknown entity.
#[test]
fn checker_rejects_malformed_xml() {
    let decl = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    for bad in [
        "<a><b></a></b>\n",
        "<a x=\"1<2\"/>\n",
        "<a>&nbsp;</a>\n",
        "<a/><b/>\n",
        "<a x=\"line\nbreak\"/>\n",
    ] {
        let doc = format!("{decl}{bad}");
        let r = std::panic::catch_unwind(|| parse(&doc));
        assert!(r.is_err(), "accepted {bad:?}");
    }
    assert_eq!(
        parse(&format!("{decl}<a x=\"&lt;&#10;\"><b/></a>\n")).len(),
        2
    );
}

/// The soak writes one suite per drawn configuration (`random-<i>.<hash>`), one case per
/// frame of each.
#[test]
fn soak_has_one_suite_per_configuration() {
    if !tools() {
        eprintln!("*** SKIPPED: EDA tools missing (scripts/install-tools.sh) ***");
        return;
    }
    let d = scratch("soak");
    let file = d.join("soak.xml");
    let o = tofprobe(&[
        "cosim",
        "--random",
        "2",
        "--seed",
        "1",
        "--frames",
        "2",
        "--simulator",
        "icarus",
        "--out",
        d.join("work").to_str().expect("utf-8"),
        "--junit",
        file.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let xml = std::fs::read_to_string(&file).expect("report");
    let els = parse(&xml);
    assert_eq!(count(&els, "testsuite"), 2);
    assert_eq!(count(&els, "testcase"), 4);
    assert_eq!(count(&els, "failure"), 0);
    let suites: Vec<&Element> = els.iter().filter(|e| e.name == "testsuite").collect();
    for (i, s) in suites.iter().enumerate() {
        let name = &s.attrs["name"];
        let hash = name
            .strip_prefix(&format!("random-{i}."))
            .unwrap_or_else(|| panic!("suite {name}"));
        assert!(hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()));
    }
}
