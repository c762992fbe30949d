// tofprobe co-simulation harness for Verilator (see testbench/README.md).
//
// Replays the golden vectors through the generated top (pixel + probe ROM + sequencer):
// per cycle it sets the inputs, evaluates with clk low, samples the outputs, raises clk and
// evaluates again (the contract's cycle). It compares, per cycle inside the trace window,
// the register writes (which registers the pixel's write-enable vector `we` selects at the
// edge, and their values at the falling edge after it, where every register file kind holds
// them) and the output pins; per digest window, a digest of both
// (everywhere); per frame, the readout. It ends with exactly one line
//   TOFPROBE-COSIM-DONE cycles=<n> frames=<n> mismatches=<n> seconds=<s> cpu_seconds=<s>
// (`seconds` wall time, `cpu_seconds` the process's CPU time, of the replay) preceded, on a mismatch, by
//   TOFPROBE-MISMATCH cycle=<c> pulse=<p> signal=<name> expected=<hex|none> actual=<hex|none>
// and/or
//   TOFPROBE-DIGEST-MISMATCH window=<w> first_pulse=<p> cycle_from=<a> cycle_to=<b>
// Compile-time settings (-D): PIX_WE, PIX_Y (expressions reaching the pixel's `we` and `y`
// from `top->rootp`), optional PIX_RST (the pixel's reset, when the top resets it in the
// middle of a frame: the directed top's `px_rst`; default the `rst` pin), TOP_HEADER,
// TOP_CLASS, optional TOFPROBE_TRACE (VCD support).
#include <chrono>
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tofprobe_harness_config.h"
#include "verilated.h"
#include TOP_HEADER
#include TOP_ROOT_HEADER
#ifdef TOFPROBE_TRACE
#include "verilated_vcd_c.h"
#endif
#ifndef PIX_RST
#define PIX_RST (top->rst)
#endif

namespace {

const uint64_t kDigestInit = 0xcbf29ce484222325ULL;
const uint64_t kDigestPrime = 0x100000001b3ULL;

inline uint64_t fold(uint64_t h, uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
    h = (h ^ a) * kDigestPrime;
    h = (h ^ b) * kDigestPrime;
    h = (h ^ c) * kDigestPrime;
    h = (h ^ d) * kDigestPrime;
    return h;
}

std::vector<std::string> read_lines(const std::string& path, bool required) {
    std::vector<std::string> out;
    std::ifstream f(path);
    if (!f) {
        if (required) {
            std::fprintf(stderr, "harness: cannot open %s\n", path.c_str());
            std::exit(2);
        }
        return out;
    }
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '/' || line[0] == '#') continue;
        out.push_back(line);
    }
    return out;
}

uint64_t hex(const std::string& s, size_t pos, size_t len) {
    return std::strtoull(s.substr(pos, len).c_str(), nullptr, 16);
}

struct Write {
    uint64_t cycle;
    uint32_t reg;
    uint64_t value;
};
struct Pins {
    uint64_t cycle;
    bool ready;
    bool rd_valid;
    uint32_t rd_index;
    uint64_t rd_data;
};

std::string hexs(uint64_t v) {
    char b[32];
    std::snprintf(b, sizeof b, "%llx", static_cast<unsigned long long>(v));
    return b;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: harness VECDIR [--bare] [--window LO HI] [--vcd FILE LO HI]\n");
        return 2;
    }
    std::string dir = argv[1];  // usage: harness VECDIR [options] [+verilator+...]
    bool bare = false;
    uint64_t win_lo = 0, win_hi = 0;
    bool win_given = false;
    std::string vcd_file;
    std::string cov_file;  // --coverage FILE: write the coverage counts (a --coverage build)
    uint64_t vcd_lo = 0, vcd_hi = 0;
    for (int i = 2; i < argc; ++i) {
        std::string a = argv[i];
        if (!a.empty() && a[0] == '+') {
            // +verilator+... run-time options (random reset, seed): VerilatedContext's.
            continue;
        } else if (a == "--coverage" && i + 1 < argc) {
            cov_file = argv[++i];
        } else if (a == "--bare") {
            bare = true;
        } else if (a == "--window" && i + 2 < argc) {
            win_lo = std::strtoull(argv[i + 1], nullptr, 10);
            win_hi = std::strtoull(argv[i + 2], nullptr, 10);
            win_given = true;
            i += 2;
        } else if (a == "--vcd" && i + 3 < argc) {
            vcd_file = argv[i + 1];
            vcd_lo = std::strtoull(argv[i + 2], nullptr, 10);
            vcd_hi = std::strtoull(argv[i + 3], nullptr, 10);
            i += 3;
        } else {
            std::fprintf(stderr, "harness: unknown argument %s\n", a.c_str());
            return 2;
        }
    }

    std::map<std::string, uint64_t> cfg;
    for (const auto& l : read_lines(dir + "/vectors.cfg", true)) {
        auto sp = l.find(' ');
        if (sp != std::string::npos) cfg[l.substr(0, sp)] = std::strtoull(l.c_str() + sp + 1, nullptr, 10);
    }
    const uint64_t R = cfg["registers"];
    const uint64_t cycles = cfg["cycles"];
    const uint64_t digest_pulses = cfg["digest_pulses"] ? cfg["digest_pulses"] : 1;
    if (!win_given) {
        win_lo = cfg["trace_from"];
        win_hi = cfg["trace_to"];
    }

    std::vector<uint32_t> stim;
    for (const auto& l : read_lines(dir + "/stimulus.hex", true)) stim.push_back(static_cast<uint32_t>(hex(l, 0, l.size())));
    std::vector<uint64_t> readout;
    for (const auto& l : read_lines(dir + "/readout.hex", true)) readout.push_back(hex(l, 0, 16));
    std::vector<Write> trace;
    std::vector<Pins> pins;
    std::vector<std::pair<uint64_t, uint64_t>> digests;
    if (!bare) {
        for (const auto& l : read_lines(dir + "/trace.hex", true)) {
            trace.push_back({hex(l, 0, 12), static_cast<uint32_t>(hex(l, 12, 4)), hex(l, 16, 16)});
        }
        for (const auto& l : read_lines(dir + "/pins.hex", true)) {
            uint64_t f = hex(l, 12, 1);
            pins.push_back({hex(l, 0, 12), (f & 1) != 0, (f & 2) != 0,
                            static_cast<uint32_t>(hex(l, 13, 3)), hex(l, 16, 16)});
        }
        for (const auto& l : read_lines(dir + "/digest.hex", true)) digests.push_back({hex(l, 0, 8), hex(l, 8, 16)});
    }

    auto ctx = std::make_unique<VerilatedContext>();
    ctx->commandArgs(argc, argv);
    auto top = std::make_unique<TOP_CLASS>(ctx.get());
#ifdef TOFPROBE_TRACE
    std::unique_ptr<VerilatedVcdC> vcd;
    if (!vcd_file.empty()) {
        ctx->traceEverOn(true);
        vcd = std::make_unique<VerilatedVcdC>();
        top->trace(vcd.get(), 99);
        vcd->open(vcd_file.c_str());
    }
#else
    if (!vcd_file.empty()) {
        std::fprintf(stderr, "harness: built without --trace, cannot write %s\n", vcd_file.c_str());
        return 2;
    }
#endif

    auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    auto cpu_secs = [&] { return static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC; };
    uint64_t mismatches = 0, frames = 0;
    bool reported = false;
    uint64_t next_pulse = 0, cur_pulse = 0;
    auto report = [&](uint64_t cyc, const std::string& sig, const std::string& exp, const std::string& act) {
        ++mismatches;
        if (!reported) {
            reported = true;
            std::printf("TOFPROBE-MISMATCH cycle=%llu pulse=%llu signal=%s expected=%s actual=%s\n",
                        static_cast<unsigned long long>(cyc), static_cast<unsigned long long>(cur_pulse),
                        sig.c_str(), exp.c_str(), act.c_str());
        }
    };

    if (bare) {
        // The bare model: the same input sequence, no observation at all.
        for (uint64_t c = 0; c < cycles; ++c) {
            top->rst = c < 2;
            uint32_t s = next_pulse < stim.size() ? stim[next_pulse] : 0;
            top->valid = (s >> 16) & 1;
            top->tdc = s & 0xffff;
            top->clk = 0;
            top->eval();
            bool p = top->pulse_o;
            top->clk = 1;
            top->eval();
            if (p) ++next_pulse;
        }
        double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("TOFPROBE-BARE cycles=%llu pulses=%llu seconds=%.6f cpu_seconds=%.6f\n",
                    static_cast<unsigned long long>(cycles), static_cast<unsigned long long>(next_pulse), secs,
                    cpu_secs());
        top->final();
        return 0;
    }

    size_t tp = 0, pp = 0;
    while (tp < trace.size() && trace[tp].cycle < win_lo) ++tp;
    while (pp < pins.size() && pins[pp].cycle < win_lo) ++pp;
    Pins prev{0, false, false, 0, 0};
    Pins exp_state{0, false, false, 0, 0};
    uint64_t window = 0, dcount = 0, dh = kDigestInit;
    uint64_t window_from_cycle = 0;
    uint64_t ro_word = 0;
    std::vector<std::pair<uint32_t, uint64_t>> act_w, exp_w;
    // Register values after the previous edge of the checked window (for unenabled writes).
    std::vector<uint64_t> y_held(R, 0);
    bool held_known = false;
    auto close_window = [&](uint64_t end_cycle) {
        if (window < digests.size()) {
            if (digests[window].first != dcount || digests[window].second != dh) {
                ++mismatches;
                std::printf("TOFPROBE-DIGEST-MISMATCH window=%llu first_pulse=%llu cycle_from=%llu cycle_to=%llu\n",
                            static_cast<unsigned long long>(window),
                            static_cast<unsigned long long>(window * digest_pulses),
                            static_cast<unsigned long long>(window_from_cycle),
                            static_cast<unsigned long long>(end_cycle));
            }
        } else {
            ++mismatches;
            std::printf("TOFPROBE-DIGEST-MISMATCH window=%llu first_pulse=%llu cycle_from=%llu cycle_to=%llu\n",
                        static_cast<unsigned long long>(window), static_cast<unsigned long long>(window * digest_pulses),
                        static_cast<unsigned long long>(window_from_cycle), static_cast<unsigned long long>(end_cycle));
        }
    };

    // The register writes of edge `cw` (enables `we`, reset `rst_w`), observed at the
    // falling edge after it: a latch register file (docs/pixel-contract.md "Register
    // file") holds a write from that falling edge on, flops and gated flops from the
    // edge itself, and every kind holds it there. Folded into the digest before the
    // next cycle's pins, the order the digest has always had.
    auto observe_writes = [&](uint64_t cw, uint64_t we, bool rst_w, bool full_w) {
        if (!full_w) {
            // Hot path of long runs: fold the writes straight into the digest.
            for (uint64_t m = we; m != 0; m &= m - 1) {
                const uint32_t r = static_cast<uint32_t>(__builtin_ctzll(m));
                dh = fold(dh, 1, cw, r, static_cast<uint64_t>(PIX_Y[r]));
                ++dcount;
            }
        } else {
            act_w.clear();
            for (uint64_t m = we; m != 0; m &= m - 1) {
                uint32_t r = static_cast<uint32_t>(__builtin_ctzll(m));
                uint64_t v = static_cast<uint64_t>(PIX_Y[r]);
                act_w.push_back({r, v});
                dh = fold(dh, 1, cw, r, v);
                ++dcount;
            }
            {
                exp_w.clear();
                while (tp < trace.size() && trace[tp].cycle == cw) {
                    exp_w.push_back({trace[tp].reg, trace[tp].value});
                    ++tp;
                }
                size_t n = act_w.size() > exp_w.size() ? act_w.size() : exp_w.size();
                for (size_t i = 0; i < n; ++i) {
                    bool ha = i < act_w.size(), he = i < exp_w.size();
                    if (ha && he && act_w[i] == exp_w[i]) continue;
                    uint32_t r = ha && he ? (act_w[i].first < exp_w[i].first ? act_w[i].first : exp_w[i].first)
                                          : (ha ? act_w[i].first : exp_w[i].first);
                    std::string e = "none", a = "none";
                    for (auto& x : exp_w) if (x.first == r) e = hexs(x.second);
                    for (auto& x : act_w) if (x.first == r) a = hexs(x.second);
                    report(cw, "y[" + std::to_string(r) + "]", e, a);
                    break;
                }
            }
            // A register whose write enable is low keeps its value: a write `we` does not
            // show (a clock gate on the wrong enable, a gate that glitches) fails at its edge.
            if (held_known && !rst_w) {
                for (uint64_t r = 0; r < R; ++r) {
                    const uint64_t v = static_cast<uint64_t>(PIX_Y[r]);
                    if (((we >> r) & 1) == 0 && v != y_held[r]) {
                        report(cw, "y[" + std::to_string(r) + "]", "none", hexs(v));
                        break;
                    }
                }
            }
            for (uint64_t r = 0; r < R; ++r) y_held[r] = static_cast<uint64_t>(PIX_Y[r]);
            held_known = true;
        }
    };
    uint64_t pend_c = 0, pend_we = 0;
    bool pend_rst = false, pend_full = false, pending = false;
    for (uint64_t c = 0; c < cycles; ++c) {
        top->rst = c < 2;
        uint32_t s = next_pulse < stim.size() ? stim[next_pulse] : 0;
        top->valid = (s >> 16) & 1;
        top->tdc = s & 0xffff;
        top->clk = 0;
        top->eval();
#ifdef TOFPROBE_TRACE
        if (vcd && c >= vcd_lo && c < vcd_hi) vcd->dump(static_cast<uint64_t>(2 * c));
#endif
        if (pending) observe_writes(pend_c, pend_we, pend_rst, pend_full);
        pending = false;
        Pins now{c, top->ready != 0, top->rd_valid != 0, static_cast<uint32_t>(top->rd_index),
                 static_cast<uint64_t>(top->rd_data)};
        const bool pulse = top->pulse_o;
        // rst wins (the pixel's, PIX_RST): a write enable during reset writes nothing (the
        // state it comes from is random until the reset edge, under +verilator+rand+reset+2).
        const bool rst_now = (PIX_RST) != 0;
        const uint64_t we = rst_now ? 0 : static_cast<uint64_t>(PIX_WE);
        top->clk = 1;
        top->eval();
#ifdef TOFPROBE_TRACE
        if (vcd && c >= vcd_lo && c < vcd_hi) vcd->dump(static_cast<uint64_t>(2 * c + 1));
#endif
        if (pulse) {
            cur_pulse = next_pulse++;
            uint64_t w = cur_pulse / digest_pulses;
            if (w != window) {
                close_window(c);
                window = w;
                window_from_cycle = c;
                dcount = 0;
                dh = kDigestInit;
            }
        }
        const bool full = c >= win_lo && c < win_hi;
        // Output pins (defined from cycle 1 on).
        if (c >= 1) {
            bool changed = c == 1 || now.ready != prev.ready || now.rd_valid != prev.rd_valid ||
                           now.rd_index != prev.rd_index || now.rd_data != prev.rd_data;
            if (changed) {
                dh = fold(dh, 2, c, static_cast<uint64_t>(now.ready) | static_cast<uint64_t>(now.rd_valid) << 1 |
                                        static_cast<uint64_t>(now.rd_index) << 2,
                          now.rd_data);
                ++dcount;
            }
            if (full) {
                // A window that starts later begins from the pins its digests vouched for.
                if (c == win_lo && c > 1) exp_state = prev;
                if (pp < pins.size() && pins[pp].cycle == c) exp_state = pins[pp++];
                if (now.ready != exp_state.ready) report(c, "ready", hexs(exp_state.ready), hexs(now.ready));
                else if (now.rd_valid != exp_state.rd_valid) report(c, "rd_valid", hexs(exp_state.rd_valid), hexs(now.rd_valid));
                else if (now.rd_index != exp_state.rd_index) report(c, "rd_index", hexs(exp_state.rd_index), hexs(now.rd_index));
                else if (now.rd_data != exp_state.rd_data) report(c, "rd_data", hexs(exp_state.rd_data), hexs(now.rd_data));
            }
            prev = now;
            if (now.rd_valid) {
                uint64_t expect = ro_word < readout.size() ? readout[ro_word] : 0;
                if (ro_word >= readout.size() || now.rd_data != expect) {
                    report(c, "readout[" + std::to_string(frames) + "][" + std::to_string(now.rd_index) + "]",
                           ro_word < readout.size() ? hexs(expect) : "none", hexs(now.rd_data));
                }
                ++ro_word;
                if (now.rd_index == R) ++frames;
            }
        }
        pend_c = c;
        pend_we = we;
        pend_rst = rst_now;
        pend_full = full;
        pending = true;
    }
    if (pending) {
        top->clk = 0;
        top->eval();
        observe_writes(pend_c, pend_we, pend_rst, pend_full);
    }
    close_window(cycles);
    if (window + 1 != digests.size()) {
        ++mismatches;
        std::printf("TOFPROBE-DIGEST-MISMATCH window=%llu first_pulse=%llu cycle_from=%llu cycle_to=%llu\n",
                    static_cast<unsigned long long>(window + 1), static_cast<unsigned long long>((window + 1) * digest_pulses),
                    static_cast<unsigned long long>(cycles), static_cast<unsigned long long>(cycles));
    }
    if (ro_word != readout.size()) {
        report(cycles, "readout_words", hexs(readout.size()), hexs(ro_word));
    }
#ifdef TOFPROBE_TRACE
    if (vcd) vcd->close();
#endif
    top->final();
#if VM_COVERAGE
    if (!cov_file.empty()) ctx->coveragep()->write(cov_file.c_str());
#endif
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("TOFPROBE-COSIM-DONE cycles=%llu frames=%llu mismatches=%llu seconds=%.6f cpu_seconds=%.6f\n",
                static_cast<unsigned long long>(cycles), static_cast<unsigned long long>(frames),
                static_cast<unsigned long long>(mismatches), secs, cpu_secs());
    return mismatches == 0 ? 0 : 1;
}
