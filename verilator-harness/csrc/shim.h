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

// A model's constructor and destructor as C symbols.
#define SEGSHADE_LIFETIME(CLASS, SYM)                                                        \
    extern "C" void* SYM##_new(uint64_t seed) { return new SegshadeModel<CLASS>(seed); }      \
    extern "C" void SYM##_free(void* h) { delete static_cast<SegshadeModel<CLASS>*>(h); }

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
    extern "C" void SYM##_step(void* h, const SegIn* in, SegOut* out) {                       \
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
    extern "C" void SYM##_step(void* h, const BfpiIn* in, BfpiOut* out) {                     \
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
    extern "C" void SYM##_step(void* h, const SpecIn* in, SpecOut* out) {                     \
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
    extern "C" void SYM##_step(void* h, const TriIn* in, FeOut* out) {                        \
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
    extern "C" void SYM##_step(void* h, const TriIn* in, TriSegOut* out) {                    \
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
    extern "C" void SYM##_step(void* h, const WrIn* in, WrOut* out) {                         \
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
    extern "C" void SYM##_step(void* h, const TriIn* in, WrOut* out) {                        \
        CLASS* m = static_cast<SegshadeModel<CLASS>*>(h)->top;                                \
        SEGSHADE_MEM_CLOCK(m, in, out, P, { SEGSHADE_TRI_PORTS(m, in) }, m->err)               \
    }

static_assert(sizeof(WrIn) == 304, "WrIn layout is mirrored in ffi.rs");
static_assert(offsetof(WrIn, pix) == 16, "WrIn layout is mirrored in ffi.rs");
static_assert(sizeof(WrOut) == 296, "WrOut layout is mirrored in ffi.rs");
static_assert(offsetof(WrOut, data) == 8, "WrOut layout is mirrored in ffi.rs");
static_assert(sizeof(TriIn) == 40, "TriIn layout is mirrored in ffi.rs");
static_assert(sizeof(FeOut) == 24, "FeOut layout is mirrored in ffi.rs");
static_assert(sizeof(TriSegOut) == 300, "TriSegOut layout is mirrored in ffi.rs");
