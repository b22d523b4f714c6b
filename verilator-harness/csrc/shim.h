// extern "C" shims between the Rust harness and verilated models: one call per clock, all
// inputs in one struct and all outputs in another. Each model gets its own VerilatedContext,
// so models are independent and may live on different threads.
//
// A per-model translation unit written by build.rs includes the model's header and expands
// one of the SEGSHADE_*_SHIM macros with the model's class and the symbol prefix.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include "verilated.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "lane buses are copied byte-wise");

// Packed lane buses of any width, copied as little-endian bytes (lane i of 8-bit lanes is
// byte i). Verilator stores buses up to 64 bits as integers and wider ones as VlWide.
template <class T> static inline void segshade_copy(uint8_t* dst, const T& v, size_t bytes) {
    std::memcpy(dst, &v, bytes);
}
template <std::size_t N> static inline void segshade_copy(uint8_t* dst, const VlWide<N>& v, size_t bytes) {
    std::memcpy(dst, v.data(), bytes);
}

// And back: bytes into a packed input bus (the bytes' unused top bits are zero).
template <class T> static inline void segshade_load(T& v, const uint8_t* src, size_t bytes) {
    v = 0;
    std::memcpy(&v, src, bytes);
}
template <std::size_t N> static inline void segshade_load(VlWide<N>& v, const uint8_t* src, size_t bytes) {
    std::memset(v.data(), 0, sizeof(EData) * N);
    std::memcpy(v.data(), src, bytes);
}

struct SegIn {
    uint32_t in_x, in_len, in_i0, in_di;  // in_di: two's complement masked to DW bits
    uint8_t rst, in_valid, out_ready;
    uint8_t keep;  // the data ports hold what the last call wrote: skip writing them
};

struct SegOut {
    uint32_t out_x;
    uint8_t in_ready, out_valid, out_last;
    uint8_t pix[256];   // lane i in byte i
    uint8_t mask[32];   // lane i in bit i % 8 of byte i / 8
};

template <class M> struct SegshadeModel {
    VerilatedContext ctx;
    M* top;
    explicit SegshadeModel(uint64_t seed) {
        // Registers start random, so a design that relies on power-up values fails its tests.
        ctx.randReset(2);
        ctx.randSeed(static_cast<int>(seed & 0x7fffffff));
        top = new M(&ctx, "top");
    }
    ~SegshadeModel() {
        top->final();
        delete top;
    }
};

// A model's constructor and destructor as C symbols. No C++ exception crosses into Rust: `new`
// returns null when construction throws (the harness refuses a null handle), and `free` and
// every `step` are noexcept, so an exception there ends the process (std::terminate) instead
// of unwinding through Rust frames.
#define SEGSHADE_LIFETIME(CLASS, SYM)                                                        \
    extern "C" void* SYM##_new(uint64_t seed) noexcept {                                      \
        try {                                                                                 \
            return new SegshadeModel<CLASS>(seed);                                            \
        } catch (...) {                                                                       \
            return nullptr;                                                                   \
        }                                                                                     \
    }                                                                                         \
    extern "C" void SYM##_free(void* h) noexcept { delete static_cast<SegshadeModel<CLASS>*>(h); }

// One clock of a streaming unit (both share SPEC §3's control ports). Inputs are applied with
// the clock low and the outputs sampled there: they are the values the rising edge sees, so a
// transfer happens in this call iff valid && ready in the result. `data` writes the data ports
// (skipped while `keep` says they still hold the last span), `sample` reads the data outputs.
template <class M, class In, class Out, class Data, class Sample>
static inline void segshade_clock(M* m, const In* in, Out* out, Data data, Sample sample) {
    m->clk = 0;
    m->rst = in->rst;
    m->in_valid = in->in_valid;
    m->out_ready = in->out_ready;
    if (!in->keep) data();
    m->eval();
    out->in_ready = m->in_ready;
    out->out_valid = m->out_valid;
    out->out_last = m->out_last;
    sample();
    m->clk = 1;
    m->eval();
}

#define SEGSHADE_SEGMENT_SHIM(CLASS, SYM, P)                                                 \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const SegIn* in, SegOut* out) noexcept {          \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        segshade_clock(                                                                       \
            m, in, out,                                                                       \
            [&] {                                                                             \
                m->in_x = in->in_x;                                                           \
                m->in_len = in->in_len;                                                       \
                m->in_i0 = in->in_i0;                                                         \
                m->in_di = in->in_di;                                                         \
            },                                                                                \
            [&] {                                                                             \
                out->out_x = m->out_x;                                                        \
                segshade_copy(out->pix, m->out_pix, P);                                       \
                segshade_copy(out->mask, m->out_mask, (P + 7) / 8);                           \
            });                                                                               \
    }

struct BfpiIn {
    uint32_t di;  // two's complement masked to DW bits
};

struct BfpiOut {
    uint8_t inc[1024];  // the packed inc bus, little-endian
};

// The BFPI is combinational: one evaluation per call, no clock.
#define SEGSHADE_BFPI_SHIM(CLASS, SYM, BYTES)                                                \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const BfpiIn* in, BfpiOut* out) noexcept {        \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        m->di = in->di;                                                                       \
        m->eval();                                                                            \
        segshade_copy(out->inc, m->inc, BYTES);                                               \
    }

struct SpecIn {
    uint32_t in_c, in_n, in_theta0, in_dtheta, in_len;  // thetas: two's complement bits
    uint8_t rst, in_valid, out_ready;
    uint8_t keep;  // the data ports hold what the last call wrote: skip writing them
};

struct SpecOut {
    uint16_t out_spec;
    uint8_t in_ready, out_valid, out_last, out_err;
};

#define SEGSHADE_SPECULAR_SHIM(CLASS, SYM)                                                   \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const SpecIn* in, SpecOut* out) noexcept {        \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        segshade_clock(                                                                       \
            m, in, out,                                                                       \
            [&] {                                                                             \
                m->in_c = in->in_c;                                                           \
                m->in_n = in->in_n;                                                           \
                m->in_theta0 = in->in_theta0;                                                 \
                m->in_dtheta = in->in_dtheta;                                                 \
                m->in_len = in->in_len;                                                       \
            },                                                                                \
            [&] {                                                                             \
                out->out_err = m->out_err;                                                    \
                out->out_spec = m->out_spec;                                                  \
            });                                                                               \
    }

// The triangle front-end (SPEC §6): three vertices in, spans out. Coordinates are two's
// complement masked to the port width (Verilator requires the bits above it to be zero).
struct TriIn {
    uint32_t x[3], y[3], i[3];
    uint8_t rst, in_valid, out_ready;
    uint8_t keep;  // the data ports hold what the last call wrote: skip writing them
};

struct FeOut {
    uint32_t out_x, out_len, out_i0, out_di;  // out_di: two's complement in DW bits
    uint32_t out_y;
    uint8_t in_ready, out_valid, err, pad;
};

#define SEGSHADE_TRI_PORTS(m, in)                                                            \
    m->in_x0 = in->x[0];                                                                      \
    m->in_y0 = in->y[0];                                                                      \
    m->in_i0 = in->i[0];                                                                      \
    m->in_x1 = in->x[1];                                                                      \
    m->in_y1 = in->y[1];                                                                      \
    m->in_i1 = in->i[1];                                                                      \
    m->in_x2 = in->x[2];                                                                      \
    m->in_y2 = in->y[2];                                                                      \
    m->in_i2 = in->i[2];

// The front-end has no out_last, so it has its own clock (same order as segshade_clock).
#define SEGSHADE_FRONTEND_SHIM(CLASS, SYM)                                                   \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const TriIn* in, FeOut* out) noexcept {           \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        m->clk = 0;                                                                           \
        m->rst = in->rst;                                                                     \
        m->in_valid = in->in_valid;                                                           \
        m->out_ready = in->out_ready;                                                         \
        if (!in->keep) {                                                                      \
            SEGSHADE_TRI_PORTS(m, in)                                                         \
        }                                                                                     \
        m->eval();                                                                            \
        out->in_ready = m->in_ready;                                                          \
        out->out_valid = m->out_valid;                                                        \
        out->err = m->err;                                                                    \
        out->out_x = m->out_x;                                                                \
        out->out_len = m->out_len;                                                            \
        out->out_i0 = m->out_i0;                                                              \
        out->out_di = m->out_di;                                                              \
        out->out_y = m->out_y;                                                                \
        m->clk = 1;                                                                           \
        m->eval();                                                                            \
    }

// tri_shader_p<P>: triangles in, segments with their y out.
struct TriSegOut {
    uint32_t out_x, out_y;
    uint8_t in_ready, out_valid, out_last, err;
    uint8_t pix[256];  // lane i in byte i
    uint8_t mask[32];  // lane i in bit i % 8 of byte i / 8
};

#define SEGSHADE_TRISHADER_SHIM(CLASS, SYM, P)                                               \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const TriIn* in, TriSegOut* out) noexcept {       \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        segshade_clock(                                                                       \
            m, in, out, [&] { SEGSHADE_TRI_PORTS(m, in) },                                    \
            [&] {                                                                             \
                out->err = m->err;                                                            \
                out->out_x = m->out_x;                                                        \
                out->out_y = m->out_y;                                                        \
                segshade_copy(out->pix, m->out_pix, P);                                       \
                segshade_copy(out->mask, m->out_mask, (P + 7) / 8);                           \
            });                                                                               \
    }

// fb_writer_p<P> (SPEC §7): segments with their y in, block writes out. The memory port's
// mem_valid/mem_ready are the driver's out_valid/out_ready.
struct WrIn {
    uint32_t in_x, in_y;
    uint8_t rst, in_valid, out_ready, keep;
    uint8_t in_last, pad[3];
    uint8_t pix[256];  // lane i in byte i
    uint8_t mask[32];  // lane i in bit i % 8 of byte i / 8
};

// The memory port of fb_writer_p<P> and tri_fb_p<P> (err: the latter's guard-band pulse).
struct WrOut {
    uint32_t mem_addr;
    uint8_t in_ready, out_valid, err, pad;
    uint8_t data[256];  // lane i in byte i
    uint8_t we[32];     // lane i in bit i % 8 of byte i / 8
};

// One clock of a unit with a memory port (same order as segshade_clock): DATA writes the data
// ports, ERR is what out->err reads.
#define SEGSHADE_MEM_CLOCK(m, in, out, P, DATA, ERR)                                         \
    m->clk = 0;                                                                               \
    m->rst = in->rst;                                                                         \
    m->in_valid = in->in_valid;                                                               \
    m->mem_ready = in->out_ready;                                                             \
    if (!in->keep) DATA                                                                       \
    m->eval();                                                                                \
    out->in_ready = m->in_ready;                                                              \
    out->err = ERR;                                                                           \
    out->out_valid = m->mem_valid;                                                            \
    out->mem_addr = m->mem_addr;                                                              \
    segshade_copy(out->data, m->mem_data, P);                                                 \
    segshade_copy(out->we, m->mem_we, (P + 7) / 8);                                           \
    m->clk = 1;                                                                               \
    m->eval();

#define SEGSHADE_WRITER_SHIM(CLASS, SYM, P)                                                  \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const WrIn* in, WrOut* out) noexcept {            \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        SEGSHADE_MEM_CLOCK(m, in, out, P, {                                                   \
            m->in_x = in->in_x;                                                               \
            m->in_y = in->in_y;                                                               \
            m->in_last = in->in_last;                                                         \
            segshade_load(m->in_pix, in->pix, P);                                             \
            segshade_load(m->in_mask, in->mask, (P + 7) / 8);                                 \
        }, 0)                                                                                 \
    }

// tri_fb_p<P>: triangles in, block writes out.
#define SEGSHADE_TRIWRITER_SHIM(CLASS, SYM, P)                                               \
    SEGSHADE_LIFETIME(CLASS, SYM)                                                             \
    extern "C" void SYM##_step(void* h, const TriIn* in, WrOut* out) noexcept {           \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        SEGSHADE_MEM_CLOCK(m, in, out, P, { SEGSHADE_TRI_PORTS(m, in) }, m->err)               \
    }

// AXI4-Stream wrappers (`generate --bus axis`): the same per-clock structs as the wrapped
// block's model, on the wrapper's ports. build.rs prints each wrapper's step from the typed
// layout (hdl_gen::axis): DATA packs the struct's fields into s_axis_tdata with
// segshade_put_bits, SAMPLE unpacks m_axis_* with segshade_get_bits and segshade_copy.
template <class M, class In, class Out, class Data, class Sample>
static inline void segshade_axis_clock(M* m, const In* in, Out* out, Data data, Sample sample) {
    m->clk = 0;
    m->rst = in->rst;
    m->s_axis_tvalid = in->in_valid;
    m->m_axis_tready = in->out_ready;
    if (!in->keep) data();
    m->eval();
    out->in_ready = m->s_axis_tready;
    out->out_valid = m->m_axis_tvalid;
    sample();
    m->clk = 1;
    m->eval();
}

// Bits [lsb, lsb + width) of a little-endian byte buffer (width <= 32). The buffers build.rs
// declares have 8 spare bytes, so the 64-bit window never reads or writes past them.
static inline uint32_t segshade_get_bits(const uint8_t* b, unsigned lsb, unsigned width) {
    uint64_t w;
    std::memcpy(&w, b + lsb / 8, 8);
    return static_cast<uint32_t>((w >> (lsb % 8)) & ((uint64_t(1) << width) - 1));
}
static inline void segshade_put_bits(uint8_t* b, unsigned lsb, unsigned width, uint32_t v) {
    uint64_t w, mask = ((uint64_t(1) << width) - 1) << (lsb % 8);
    std::memcpy(&w, b + lsb / 8, 8);
    w = (w & ~mask) | ((uint64_t(v) << (lsb % 8)) & mask);
    std::memcpy(b + lsb / 8, &w, 8);
}

// The per-clock structs' layout, stated once: every field's offset and every struct's size.
// The C++ compiler checks them here; build.rs reads these lines and has the Rust compiler check
// the same numbers against ffi.rs's #[repr(C)] structs (generated `const` asserts in models.rs),
// so neither side can drift from the other. A new field gets a line here.
#define SEGSHADE_OFFSET(S, F, N) static_assert(offsetof(S, F) == N, #S "." #F " is at byte " #N " (ffi.rs agrees)")
#define SEGSHADE_SIZE(S, N) static_assert(sizeof(S) == N, #S " is " #N " bytes (ffi.rs agrees)")
SEGSHADE_OFFSET(SegIn, in_x, 0);
SEGSHADE_OFFSET(SegIn, in_len, 4);
SEGSHADE_OFFSET(SegIn, in_i0, 8);
SEGSHADE_OFFSET(SegIn, in_di, 12);
SEGSHADE_OFFSET(SegIn, rst, 16);
SEGSHADE_OFFSET(SegIn, in_valid, 17);
SEGSHADE_OFFSET(SegIn, out_ready, 18);
SEGSHADE_OFFSET(SegIn, keep, 19);
SEGSHADE_SIZE(SegIn, 20);
SEGSHADE_OFFSET(SegOut, out_x, 0);
SEGSHADE_OFFSET(SegOut, in_ready, 4);
SEGSHADE_OFFSET(SegOut, out_valid, 5);
SEGSHADE_OFFSET(SegOut, out_last, 6);
SEGSHADE_OFFSET(SegOut, pix, 7);
SEGSHADE_OFFSET(SegOut, mask, 263);
SEGSHADE_SIZE(SegOut, 296);
SEGSHADE_OFFSET(BfpiIn, di, 0);
SEGSHADE_SIZE(BfpiIn, 4);
SEGSHADE_OFFSET(BfpiOut, inc, 0);
SEGSHADE_SIZE(BfpiOut, 1024);
SEGSHADE_OFFSET(SpecIn, in_c, 0);
SEGSHADE_OFFSET(SpecIn, in_n, 4);
SEGSHADE_OFFSET(SpecIn, in_theta0, 8);
SEGSHADE_OFFSET(SpecIn, in_dtheta, 12);
SEGSHADE_OFFSET(SpecIn, in_len, 16);
SEGSHADE_OFFSET(SpecIn, rst, 20);
SEGSHADE_OFFSET(SpecIn, in_valid, 21);
SEGSHADE_OFFSET(SpecIn, out_ready, 22);
SEGSHADE_OFFSET(SpecIn, keep, 23);
SEGSHADE_SIZE(SpecIn, 24);
SEGSHADE_OFFSET(SpecOut, out_spec, 0);
SEGSHADE_OFFSET(SpecOut, in_ready, 2);
SEGSHADE_OFFSET(SpecOut, out_valid, 3);
SEGSHADE_OFFSET(SpecOut, out_last, 4);
SEGSHADE_OFFSET(SpecOut, out_err, 5);
SEGSHADE_SIZE(SpecOut, 6);
SEGSHADE_OFFSET(TriIn, x, 0);
SEGSHADE_OFFSET(TriIn, y, 12);
SEGSHADE_OFFSET(TriIn, i, 24);
SEGSHADE_OFFSET(TriIn, rst, 36);
SEGSHADE_OFFSET(TriIn, in_valid, 37);
SEGSHADE_OFFSET(TriIn, out_ready, 38);
SEGSHADE_OFFSET(TriIn, keep, 39);
SEGSHADE_SIZE(TriIn, 40);
SEGSHADE_OFFSET(FeOut, out_x, 0);
SEGSHADE_OFFSET(FeOut, out_len, 4);
SEGSHADE_OFFSET(FeOut, out_i0, 8);
SEGSHADE_OFFSET(FeOut, out_di, 12);
SEGSHADE_OFFSET(FeOut, out_y, 16);
SEGSHADE_OFFSET(FeOut, in_ready, 20);
SEGSHADE_OFFSET(FeOut, out_valid, 21);
SEGSHADE_OFFSET(FeOut, err, 22);
SEGSHADE_OFFSET(FeOut, pad, 23);
SEGSHADE_SIZE(FeOut, 24);
SEGSHADE_OFFSET(TriSegOut, out_x, 0);
SEGSHADE_OFFSET(TriSegOut, out_y, 4);
SEGSHADE_OFFSET(TriSegOut, in_ready, 8);
SEGSHADE_OFFSET(TriSegOut, out_valid, 9);
SEGSHADE_OFFSET(TriSegOut, out_last, 10);
SEGSHADE_OFFSET(TriSegOut, err, 11);
SEGSHADE_OFFSET(TriSegOut, pix, 12);
SEGSHADE_OFFSET(TriSegOut, mask, 268);
SEGSHADE_SIZE(TriSegOut, 300);
SEGSHADE_OFFSET(WrIn, in_x, 0);
SEGSHADE_OFFSET(WrIn, in_y, 4);
SEGSHADE_OFFSET(WrIn, rst, 8);
SEGSHADE_OFFSET(WrIn, in_valid, 9);
SEGSHADE_OFFSET(WrIn, out_ready, 10);
SEGSHADE_OFFSET(WrIn, keep, 11);
SEGSHADE_OFFSET(WrIn, in_last, 12);
SEGSHADE_OFFSET(WrIn, pad, 13);
SEGSHADE_OFFSET(WrIn, pix, 16);
SEGSHADE_OFFSET(WrIn, mask, 272);
SEGSHADE_SIZE(WrIn, 304);
SEGSHADE_OFFSET(WrOut, mem_addr, 0);
SEGSHADE_OFFSET(WrOut, in_ready, 4);
SEGSHADE_OFFSET(WrOut, out_valid, 5);
SEGSHADE_OFFSET(WrOut, err, 6);
SEGSHADE_OFFSET(WrOut, pad, 7);
SEGSHADE_OFFSET(WrOut, data, 8);
SEGSHADE_OFFSET(WrOut, we, 264);
SEGSHADE_SIZE(WrOut, 296);
