// A native C++ Verilator testbench: the reference point of scripts/bench-cosim.
//
// It drives the verilated model (class Vdut) from a stimulus file written by `bench gen` and
// compares every output with the expected-output file written next to it, under the traffic of
// verilator_harness::traffic (xorshift32, two draws per clock: offer, then out_ready). It runs
// the clock exactly as the harness's shim does: inputs applied with clk low, eval, outputs
// sampled, clk high, eval. Only the clock loop and the comparison are timed.
//
// Built once per design with
//   verilator --cc --exe --build --prefix Vdut -CFLAGS -DBENCH_DESIGN=0 -CFLAGS -DBENCH_P=8 ...
// (segment_shader_p<BENCH_P>) or -DBENCH_DESIGN=1 (specular_unit). The two designs share the
// loop; each contributes a small traits struct whose members are templates, so only the one
// the build uses is instantiated against the model's ports.
//
// Usage: native_tb STIM EXPECT [SPANS]   (SPANS: only the first SPANS spans; 0 or absent: all)
// Prints: RESULT impl=native model=... spans=... clocks=... pixels=... secs=... cpu=... mismatches=...
// (secs: wall time of the loop; cpu: this thread's CPU time in it).

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <vector>

#include "Vdut.h"
#include "verilated.h"

#ifndef BENCH_DESIGN
#error "define BENCH_DESIGN: 0 segment shader, 1 specular unit"
#endif

static std::vector<uint8_t> slurp(const char* path) {
    FILE* f = std::fopen(path, "rb");
    if (!f) {
        std::fprintf(stderr, "native_tb: cannot open %s\n", path);
        std::exit(2);
    }
    std::vector<uint8_t> data;
    uint8_t buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) data.insert(data.end(), buf, buf + n);
    std::fclose(f);
    return data;
}

// CPU time of this thread: on a shared machine a steadier measure than the wall clock.
static double thread_cpu() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static uint32_t le32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}
static uint64_t le64(const uint8_t* p) {
    uint64_t v;
    std::memcpy(&v, p, 8);
    return v;
}

// verilator_harness::traffic: xorshift32 (13, 17, 5); thresholds in 256ths.
struct Traffic {
    uint32_t state, valid_thr, ready_thr;
    bool offer = false, ready = false;
    uint32_t word() {
        uint32_t x = state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        return state = x;
    }
    void clock() {
        offer = (word() >> 24) < valid_thr;
        ready = (word() >> 24) < ready_thr;
    }
};

struct Stim {
    uint32_t port[5], outputs, triangle, y;
};

// Packed lane buses as little-endian bytes (Verilator keeps <= 64 bits in integers, wider in VlWide).
template <class T> static inline void bytes_of(uint8_t* dst, const T& v, size_t n) { std::memcpy(dst, &v, n); }
template <std::size_t N> static inline void bytes_of(uint8_t* dst, const VlWide<N>& v, size_t n) {
    std::memcpy(dst, v.data(), n);
}

// segment_shader_p<P>: expected record = u32 out_x | out_last << 31, mask bytes, P pixel bytes.
template <unsigned P> struct SegmentDesign {
    static constexpr uint32_t design = 0, lanes = P;
    static constexpr unsigned mask_bytes = (P + 7) / 8;
    static constexpr size_t record = (4 + mask_bytes + P + 3) / 4 * 4;
    static const char* name() {
        static char buf[32];
        std::snprintf(buf, sizeof buf, "segment_shader_p%u", P);
        return buf;
    }
    template <class M> static void drive(M* m, const Stim& s) {
        m->in_x = s.port[0];
        m->in_len = s.port[1];
        m->in_i0 = s.port[2];
        m->in_di = s.port[3];
    }
    // Pixels compared (in-span lanes), or -1 on a mismatch.
    template <class M> static int check(const M* m, const uint8_t* r) {
        const uint32_t xl = le32(r);
        if (m->out_x != (xl & 0x7fffffffu) || m->out_last != (xl >> 31)) return -1;
        uint8_t mask[mask_bytes], pix[P];
        bytes_of(mask, m->out_mask, mask_bytes);
        bytes_of(pix, m->out_pix, P);
        const uint8_t* want_mask = r + 4;
        const uint8_t* want_pix = r + 4 + mask_bytes;
        if (std::memcmp(mask, want_mask, mask_bytes) != 0) return -1;
        int pixels = 0;
        for (unsigned i = 0; i < P; i++) {
            if (want_mask[i / 8] >> (i % 8) & 1) {
                pixels++;
                if (pix[i] != want_pix[i]) return -1;
            }
        }
        return pixels;
    }
};

// specular_unit: expected record = u16 out_spec, u8 out_err, u8 out_last.
struct SpecularDesign {
    static constexpr uint32_t design = 1, lanes = 1;
    static constexpr size_t record = 4;
    static const char* name() { return "specular_unit"; }
    template <class M> static void drive(M* m, const Stim& s) {
        m->in_c = s.port[0];
        m->in_n = s.port[1];
        m->in_theta0 = s.port[2];
        m->in_dtheta = s.port[3];
        m->in_len = s.port[4];
    }
    template <class M> static int check(const M* m, const uint8_t* r) {
        const uint16_t spec = uint16_t(r[0] | r[1] << 8);
        return (m->out_spec == spec && m->out_err == r[2] && m->out_last == r[3]) ? 1 : -1;
    }
};

#if BENCH_DESIGN == 0
using Design = SegmentDesign<BENCH_P>;
#else
using Design = SpecularDesign;
#endif

static constexpr uint64_t DRAIN_CLOCKS = 3;  // as the harness: quiet clocks after the last output
static constexpr uint64_t STALL_LIMIT = 10000;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: native_tb STIM EXPECT [SPANS]\n");
        return 2;
    }
    const std::vector<uint8_t> stim_file = slurp(argv[1]);
    const std::vector<uint8_t> expect_file = slurp(argv[2]);
    // Formats 1 and 2 (bench.rs): format 2 puts its model's description between the fixed
    // 64 bytes and the records, and says where the records start.
    const bool format2 = stim_file.size() >= 64 && std::memcmp(stim_file.data(), "SSBSTIM2", 8) == 0;
    if (stim_file.size() < 64 || (!format2 && std::memcmp(stim_file.data(), "SSBSTIM1", 8) != 0) || expect_file.size() < 24 ||
        std::memcmp(expect_file.data(), "SSBEXPT1", 8) != 0) {
        std::fprintf(stderr, "native_tb: not bench stimulus/expected files\n");
        return 2;
    }
    const uint8_t* h = stim_file.data();
    const size_t records_at = format2 ? le32(h + 56) : 64;
    const uint32_t design = le32(h + 8), p = le32(h + 12);
    Traffic traffic{le32(h + 16), le32(h + 20), le32(h + 24)};
    size_t spans = le32(h + 28);
    const uint64_t seed = le64(h + 40);
    if (design != Design::design || p != Design::lanes || le32(expect_file.data() + 12) != Design::record) {
        std::fprintf(stderr, "native_tb: the files are for another design (design %u, p %u)\n", design, p);
        return 2;
    }
    if (argc > 3 && std::atol(argv[3]) > 0 && size_t(std::atol(argv[3])) < spans) spans = std::atol(argv[3]);
    if (stim_file.size() < records_at + spans * sizeof(Stim)) {
        std::fprintf(stderr, "native_tb: stimulus file too short\n");
        return 2;
    }
    std::vector<Stim> stims(spans);
    std::memcpy(stims.data(), h + records_at, spans * sizeof(Stim));
    uint64_t total = 0;
    for (const Stim& s : stims) total += s.outputs;
    const uint8_t* expect = expect_file.data() + 24;
    if (le64(expect_file.data() + 16) < total) {
        std::fprintf(stderr, "native_tb: expected file too short\n");
        return 2;
    }

    VerilatedContext ctx;
    ctx.randReset(2);
    ctx.randSeed(int(seed & 0x7fffffff));
    Vdut* m = new Vdut{&ctx, "top"};
    // Two clocks of reset with the inputs idle, as the harness.
    m->in_valid = 0;
    m->out_ready = 0;
    m->rst = 1;
    for (int i = 0; i < 2; i++) {
        m->clk = 0;
        m->eval();
        m->clk = 1;
        m->eval();
    }
    m->rst = 0;

    uint64_t clocks = 0, pixels = 0, checked = 0, owed = 0, mismatches = 0, idle = 0, drain = 0;
    size_t next = 0;
    bool offering = false;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu();
    for (;;) {
        if (next == spans && checked == owed) {
            if (drain == DRAIN_CLOCKS) break;
            drain++;
        }
        traffic.clock();
        if (!offering && next < spans) {
            offering = traffic.offer;
            if (offering) Design::drive(m, stims[next]);
        }
        m->in_valid = offering;
        m->out_ready = traffic.ready;
        m->clk = 0;
        m->eval();
        clocks++;
        bool progress = false;
        if (m->out_valid && traffic.ready) {
            progress = true;
            if (checked < owed) {
                const int n = Design::check(m, expect + checked * Design::record);
                if (n < 0) {
                    if (mismatches < 10)
                        std::fprintf(stderr, "MISMATCH output %llu (clock %llu)\n", (unsigned long long)checked,
                                     (unsigned long long)clocks);
                    mismatches++;
                } else {
                    pixels += n;
                }
                checked++;
            } else {
                mismatches++;
                std::fprintf(stderr, "MISMATCH output with nothing outstanding (clock %llu)\n", (unsigned long long)clocks);
            }
        }
        if (offering && m->in_ready) {
            progress = true;
            owed += stims[next].outputs;
            next++;
            offering = false;
        }
        m->clk = 1;
        m->eval();
        idle = progress ? 0 : idle + 1;
        if (idle > STALL_LIMIT) {
            std::fprintf(stderr, "MISMATCH no transfer for %llu clocks\n", (unsigned long long)STALL_LIMIT);
            mismatches++;
            break;
        }
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = thread_cpu() - cpu_start;
    std::printf("RESULT impl=native model=%s spans=%zu clocks=%llu pixels=%llu secs=%.6f cpu=%.6f mismatches=%llu\n",
                Design::name(), next, (unsigned long long)clocks, (unsigned long long)pixels, secs, cpu,
                (unsigned long long)mismatches);
    m->final();
    delete m;
    return mismatches ? 1 : 0;
}
