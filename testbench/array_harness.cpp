// tofprobe array co-simulation harness for Verilator (docs/pixel-contract.md "Array";
// crates/cosim/src/array.rs builds it, cached by content hash).
//
// Replays the array's golden vectors (tofprobe_array::rtl_vectors) through the generated
// `tofprobe_array`, cycle by cycle at its ports: it presents the next pulse's detections in
// the cycles where the model says the pixels sample (`pulse_o`), evaluates with clk low,
// compares pulse_o, ready, ro_valid and ro_data with the model's, raises clk and evaluates
// again. It ends with exactly one line
//   TOFPROBE-COSIM-DONE cycles=<n> mismatches=<n> seconds=<s>
// preceded, for each of the first 10 mismatches, by
//   TOFPROBE-MISMATCH cycle=<c> signal=<name> expected=<hex> actual=<hex>
// Usage: harness VECTORS_DIR [+verilator+rand+reset+2 +verilator+seed+N]. Compile-time settings (-D): TOP_HEADER, TOP_CLASS.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "verilated.h"
#include TOP_HEADER

namespace {

std::vector<std::string> read_lines(const std::string& path) {
    std::vector<std::string> out;
    std::ifstream f(path);
    if (!f) {
        std::fprintf(stderr, "harness: cannot open %s\n", path.c_str());
        std::exit(2);
    }
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '/' || line[0] == '#' || line[0] == '`') continue;
        out.push_back(line);
    }
    return out;
}

// The `define values of array_params.vh.
std::map<std::string, std::string> read_defines(const std::string& path) {
    std::map<std::string, std::string> d;
    std::ifstream f(path);
    if (!f) {
        std::fprintf(stderr, "harness: cannot open %s\n", path.c_str());
        std::exit(2);
    }
    std::string line;
    while (std::getline(f, line)) {
        if (line.rfind("`define ", 0) != 0) continue;
        size_t a = line.find(' ', 8);
        if (a == std::string::npos) continue;
        d[line.substr(8, a - 8)] = line.substr(a + 1);
    }
    return d;
}

// A hex number of any width as little-endian 32-bit words.
std::vector<uint32_t> hex_words(const std::string& s) {
    std::vector<uint32_t> w;
    uint32_t cur = 0;
    int bits = 0;
    for (size_t i = s.size(); i-- > 0;) {
        char c = s[i];
        int v;
        if (c >= '0' && c <= '9') v = c - '0';
        else if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
        else if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
        else continue;
        cur |= uint32_t(v) << bits;
        bits += 4;
        if (bits == 32) {
            w.push_back(cur);
            cur = 0;
            bits = 0;
        }
    }
    if (bits) w.push_back(cur);
    return w;
}

// Bits [lo, lo + width) of `w`, as little-endian 32-bit words.
std::vector<uint32_t> slice(const std::vector<uint32_t>& w, size_t lo, size_t width) {
    std::vector<uint32_t> out((width + 31) / 32, 0);
    for (size_t b = 0; b < width; ++b) {
        size_t s = lo + b;
        if (s / 32 < w.size() && ((w[s / 32] >> (s % 32)) & 1)) out[b / 32] |= 1u << (b % 32);
    }
    return out;
}

template <typename T>
void put(T& sig, const std::vector<uint32_t>& w) {
    static_assert(std::is_integral<T>::value, "a narrow port");
    uint64_t v = (w.empty() ? 0 : w[0]) | (w.size() > 1 ? uint64_t(w[1]) << 32 : 0);
    sig = static_cast<T>(v);
}

template <std::size_t N>
void put(VlWide<N>& sig, const std::vector<uint32_t>& w) {
    for (std::size_t i = 0; i < N; ++i) sig[i] = i < w.size() ? w[i] : 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: harness VECTORS_DIR\n");
        return 2;
    }
    const std::string dir = argv[1];
    auto defs = read_defines(dir + "/array_params.vh");
    // The inputs: the pixels, or with a superpixel (G > 1) their SPADs (AR_NS).
    const size_t np = std::stoul(defs.count("AR_NS") ? defs["AR_NS"] : defs["AR_NP"]);
    const size_t t = std::stoul(defs["AR_T"]);
    const size_t b = std::stoul(defs["AR_B"]);
    const uint64_t cycles = std::stoull(defs["AR_CYCLES"]);
    // A reset in the middle of the first frame (AR_RESET_AT, when the vectors have one):
    // one cycle of rst beside power-up's two.
    const bool has_reset = defs.count("AR_RESET_AT") != 0;
    const uint64_t reset_at = has_reset ? std::stoull(defs["AR_RESET_AT"]) : 0;
    auto stim = read_lines(dir + "/array_stim.hex");
    auto expect = read_lines(dir + "/array_expect.hex");
    if (expect.size() != cycles) {
        std::fprintf(stderr, "harness: %zu expected lines for %llu cycles\n", expect.size(),
                     (unsigned long long)cycles);
        return 2;
    }
    const uint64_t bmask = b >= 64 ? ~0ULL : ((1ULL << b) - 1);
    auto ctx = std::make_unique<VerilatedContext>();
    // +verilator+rand+reset+2 +verilator+seed+N: randomised initial values (the reset must
    // clear every register the ports show).
    ctx->commandArgs(argc, argv);
    auto top = std::make_unique<TOP_CLASS>(ctx.get());
    auto t0 = std::chrono::steady_clock::now();
    uint64_t mism = 0;
    size_t pidx = 0;
    std::vector<uint32_t> none;
    auto report = [&](uint64_t cycle, const char* name, uint64_t e, uint64_t a) {
        if (mism < 10)
            std::printf("TOFPROBE-MISMATCH cycle=%llu signal=%s expected=%llx actual=%llx\n",
                        (unsigned long long)cycle, name, (unsigned long long)e,
                        (unsigned long long)a);
        ++mism;
    };
    // The clock starts high: Verilator's first eval settles the model without an edge, so
    // cycle 0's rise is the first edge everywhere. Starting low, a hierarchically Verilated
    // pixel (its own model, `cosim::array::build`) missed that first edge.
    top->clk = 1;
    top->rst = 1;
    top->eval();
    for (uint64_t cycle = 0; cycle < cycles; ++cycle) {
        unsigned p = 0, r = 0, v = 0;
        unsigned long long d = 0;
        if (std::sscanf(expect[cycle].c_str(), "%x %x %x %llx", &p, &r, &v, &d) != 4) {
            std::fprintf(stderr, "harness: bad expected line %llu\n", (unsigned long long)cycle);
            return 2;
        }
        top->rst = cycle < 2 || (has_reset && cycle == reset_at);
        if (p && pidx < stim.size()) {
            auto w = hex_words(stim[pidx++]);
            put(top->valid, slice(w, 0, np));
            put(top->tdc, slice(w, np, np * t));
        } else {
            put(top->valid, none);
            put(top->tdc, none);
        }
        top->clk = 0;
        top->eval();
        // Before the first edge (cycle 0) the registers hold no value yet (Verilator's
        // randomised start): compared from the cycle after the first reset edge.
        if (cycle > 0) {
            if (top->pulse_o != p) report(cycle, "pulse_o", p, top->pulse_o);
            if (top->ready != r) report(cycle, "ready", r, top->ready);
            if (top->ro_valid != v) report(cycle, "ro_valid", v, top->ro_valid);
            if ((uint64_t(top->ro_data) & bmask) != (d & bmask))
                report(cycle, "ro_data", d & bmask, uint64_t(top->ro_data) & bmask);
        }
        top->clk = 1;
        top->eval();
    }
    top->final();
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("TOFPROBE-COSIM-DONE cycles=%llu mismatches=%llu seconds=%.3f\n",
                (unsigned long long)cycles, (unsigned long long)mism, s);
    return 0;
}
