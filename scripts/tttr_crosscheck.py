"""Compares tofprobe's tttr decoder (the tttr_dump example's JSON) with independent readers.

PTU files: ptufile (Christoph Gohlke, BSD-3-Clause). SPC files: phconvert's SPC-1xx
algorithm (bhreader._read_32_nonQC_records, MIT), transcribed below with numpy.
Usage: python tttr_crosscheck.py DUMP_BINARY FILE...
"""

import copy
import json
import subprocess
import sys

import logging

import numpy as np

# ptufile warns about the sample files' out-of-order UsrHeadName tags; not our concern.
logging.getLogger("ptufile").setLevel(logging.ERROR)

FIRST = 10  # photons compared one by one


def ours(dump, path):
    out = subprocess.run([dump, path, str(4 * FIRST)], check=True, capture_output=True, text=True)
    d = json.loads(out.stdout)
    photons = []
    for ev in d["first_events"]:
        if "T3Photon" in ev:
            e = ev["T3Photon"]
            photons.append((e["sync"], e["dtime"], e["channel"]))
        elif "T2Photon" in ev:
            e = ev["T2Photon"]
            photons.append((e["time"], e["channel"]))
    c = d["summary"]["counts"]
    return {
        "records": c["records"],
        "photons": c["photons"],
        "markers": c["markers"],
        "overflow_records": c["overflow_records"],
        "first_photons": photons[:FIRST],
        "resolution_s": d["summary"]["resolution_s"],
        "global_resolution_s": d["summary"]["global_resolution_s"],
        "sync_rate_hz": d["summary"]["sync_rate_hz"] or 0,
        "decode_records_per_s": d["decode_records_per_s"],
    }


def theirs_ptu(path):
    import ptufile

    with ptufile.PtuFile(path) as p:
        r = p.decode_records()
        t3 = p.is_t3
        photon = r["channel"] >= 0
        marker = r["marker"] > 0
        ph = r[photon][:FIRST]
        if t3:
            first = [(int(x["time"]), int(x["dtime"]), int(x["channel"])) for x in ph]
        else:
            first = [(int(x["time"]), int(x["channel"])) for x in ph]
        return {
            "records": int(p.number_records),
            "photons": int(photon.sum()),
            "markers": int(marker.sum()),
            "overflow_records": int((~photon & ~marker).sum()),
            "first_photons": first,
            "resolution_s": float(p.tcspc_resolution if t3 else p.global_resolution),
            "global_resolution_s": float(p.global_resolution),
            "sync_rate_hz": int(p.syncrate),
        }


def theirs_spc(path):
    """phconvert's SPC-1xx reader, transcribed; photons = valid records, not markers."""
    raw = np.fromfile(path, dtype="<u4")
    header, rec = raw[0], raw[1:]
    ts = (rec & 0xFFF).astype(np.uint64)
    ovfl = ((rec & 0xC0000000) >> 30).astype(np.uint8)
    ts += np.left_shift(np.cumsum((ovfl == 0b11) * (rec & 0x0FFFFFFF).astype(np.uint64)), 12)
    valid = (ovfl & 0b10) == 0
    ts, rec, ovfl = ts[valid], rec[valid], ovfl[valid]
    ts += np.left_shift(np.cumsum(ovfl, dtype=np.uint64), 12)
    routing = (rec & 0xF000) >> 12
    adc = (rec & 0x0FFF0000) >> 16
    marker = (rec & 0x10000000) != 0
    photon = ~marker
    first = [(int(t), int(4095 - a), int(c)) for t, a, c in
             zip(ts[photon][:FIRST], adc[photon][:FIRST], routing[photon][:FIRST])]
    n = len(raw) - 1
    over = ((raw[1:] & 0xC0000000) >> 30)
    return {
        "records": n,
        "photons": int(photon.sum()),
        "markers": int(marker.sum()),
        "overflow_records": int((over == 0b11).sum() + (over == 0b01).sum()),
        "first_photons": first,
        "resolution_s": None,
        "global_resolution_s": float(header & 0x00FFFFFF) / 1e10,
        "sync_rate_hz": 0,
    }


def compare(a, b):
    """Differences between our result a and the reference b, as text lines."""
    bad = []
    for k, v in b.items():
        x = a[k]
        if isinstance(v, float) or isinstance(x, float):
            # Both read the same f64 from the header: equal to the last bit.
            if (x is None) != (v is None) or (v is not None and x != v):
                bad.append(f"{k}: ours {x!r}, reference {v!r}")
        elif x != v:
            bad.append(f"{k}: ours {x!r}, reference {v!r}")
    return bad


def main():
    dump, files = sys.argv[1], sys.argv[2:]
    failed = 0
    for path in files:
        a = ours(dump, path)
        b = theirs_spc(path) if path.lower().endswith(".spc") else theirs_ptu(path)
        bad = compare(a, b)
        # The check can fail: one photon more must be caught.
        broken = copy.deepcopy(a)
        broken["photons"] += 1
        if not compare(broken, b):
            bad.append("self-test: a perturbed photon count was not caught")
        name = path.rsplit("/", 1)[-1]
        if bad:
            failed += 1
            print(f"tttr-crosscheck: MISMATCH {name}")
            for line in bad:
                print(f"  {line}")
        else:
            print(f"tttr-crosscheck: ok {name}: {a['records']} records, {a['photons']} photons, "
                  f"{a['overflow_records']} overflow records, {a['markers']} markers, first "
                  f"{len(a['first_photons'])} photons and resolutions equal "
                  f"(decode {a['decode_records_per_s'] / 1e6:.1f} M records/s)")
    if failed:
        print(f"tttr-crosscheck: {failed} of {len(files)} files differ")
        sys.exit(1)
    print(f"tttr-crosscheck: all {len(files)} files agree")


if __name__ == "__main__":
    main()
