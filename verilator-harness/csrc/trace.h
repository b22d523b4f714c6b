// Traced models: the shims of shim.h on a model built with `verilator --trace-fst`, which dumps
// every evaluation into an FST file while one is open, and C entry points to open and close it.
// build.rs builds such a twin of every streaming model when COSIM_TRACE is set at build time
// (and of seg_p2_span always, for the test suite); untraced models never include this file, so
// they are compiled exactly as without it.
//
// Time in the file, in ns: clock N (counted from 0 at the model's construction, reset clocks
// included) has its inputs applied with `clk` low at t = 10 N and its rising edge at
// t = 10 N + 5 (a 100 MHz clock on screen).
//
// No C++ exception crosses into Rust: the entry points that can fail catch everything and
// return an error, and `step` and `free` are noexcept (an exception there ends the process
// with std::terminate instead of unwinding into Rust).

#include <cstdint>
#include "verilated_fst_c.h"

// Verilator wants tracing enabled in the context before the model is built: this base class
// of SegshadeTraced does it first.
struct SegshadeTraceOn {
    explicit SegshadeTraceOn(VerilatedContext* ctx) { ctx->traceEverOn(true); }
};

// The verilated class M with its FST. shim.h's clock calls `eval` twice per clock (clk low,
// then high); this `eval` hides M's and dumps after each one while a file is open.
template <class M> struct SegshadeTraced : SegshadeTraceOn, M {
    VerilatedFstC* fst = nullptr;
    uint64_t half = 0;  // evaluations so far; the clock is half / 2
    SegshadeTraced(VerilatedContext* ctx, const char* name) : SegshadeTraceOn(ctx), M(ctx, name) {}
    ~SegshadeTraced() { close(); }
    void eval() {
        M::eval();
        if (fst) fst->dump(half * 5);
        ++half;
    }
    void close() {
        if (!fst) return;
        fst->close();
        delete fst;
        fst = nullptr;
    }
};

// The C symbols of a traced twin. shim.h's macro, expanded on SegshadeTraced<CLASS> with the
// symbol prefix SYM##_raw, defines the model's clock; these wrap its new/step/free so nothing
// throws across, and add the FST's open and close.
//
// SYM_trace_open(h, path, clock): the next `step` is clock `clock` (so the file's times are the
// run's), and every evaluation from then on goes into the FST at `path`, replacing one already
// open. Returns 0, or 1 when the file cannot be created, 2 on any other error.
// SYM_trace_close(h): flushes and closes the file (also done by `free`). Returns 0, or 2.
#define SEGSHADE_TRACE_SHIM(CLASS, SYM, IN, OUT)                                              \
    extern "C" void* SYM##_new(uint64_t seed) noexcept {                                      \
        try {                                                                                 \
            return SYM##_raw_new(seed);                                                       \
        } catch (...) {                                                                       \
            return nullptr;                                                                   \
        }                                                                                     \
    }                                                                                         \
    extern "C" void SYM##_free(void* h) noexcept { SYM##_raw_free(h); }                       \
    extern "C" void SYM##_step(void* h, const IN* in, OUT* out) noexcept {                    \
        SYM##_raw_step(h, in, out);                                                           \
    }                                                                                         \
    extern "C" int SYM##_trace_open(void* h, const char* path, uint64_t clock) noexcept {     \
        try {                                                                                 \
            SegshadeTraced<CLASS>* m = static_cast<SegshadeModel<SegshadeTraced<CLASS>>*>(h)->top; \
            m->close();                                                                       \
            VerilatedFstC* fst = new VerilatedFstC;                                           \
            fst->set_time_unit("1ns");                                                        \
            fst->set_time_resolution("1ns");                                                  \
            m->trace(fst, 99);                                                                \
            fst->open(path);                                                                  \
            if (!fst->isOpen()) {                                                             \
                delete fst;                                                                   \
                return 1;                                                                     \
            }                                                                                 \
            m->fst = fst;                                                                     \
            m->half = 2 * clock;                                                              \
            return 0;                                                                         \
        } catch (...) {                                                                       \
            return 2;                                                                         \
        }                                                                                     \
    }                                                                                         \
    extern "C" int SYM##_trace_close(void* h) noexcept {                                      \
        try {                                                                                 \
            static_cast<SegshadeModel<SegshadeTraced<CLASS>>*>(h)->top->close();              \
            return 0;                                                                         \
        } catch (...) {                                                                       \
            return 2;                                                                         \
        }                                                                                     \
    }
