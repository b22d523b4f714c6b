"""cocotb side of scripts/bench-cosim: the same stimulus, traffic and expected outputs as the
harness and the native testbench, under Icarus Verilog.

Reads the files written by `bench gen` (layout in verilator-harness/src/benchfile.rs):
BENCH_STIM, BENCH_EXPECT; BENCH_SPANS streams only the first N spans (0: all); the result line
(`RESULT impl=cocotb ...`, as the other two print) goes to BENCH_RESULT.

The traffic is verilator_harness::traffic: xorshift32, two draws per clock (offer, then
out_ready), thresholds in 256ths. As in the harness's shim, inputs are applied with the clock
low and the outputs sampled once they settle; a transfer happens at the next rising edge when
valid and ready are both high.
"""

import os
import struct
import time

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly

DRAIN_CLOCKS = 3
STALL_LIMIT = 10_000


class Traffic:
    def __init__(self, state, valid_thr, ready_thr):
        self.state, self.valid_thr, self.ready_thr = state, valid_thr, ready_thr

    def word(self):
        x = self.state
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        self.state = x
        return x

    def clock(self):
        offer = (self.word() >> 24) < self.valid_thr
        ready = (self.word() >> 24) < self.ready_thr
        return offer, ready


def read_files():
    with open(os.environ["BENCH_STIM"], "rb") as f:
        stim = f.read()
    with open(os.environ["BENCH_EXPECT"], "rb") as f:
        expect = f.read()
    assert stim[:8] in (b"SSBSTIM1", b"SSBSTIM2") and expect[:8] == b"SSBEXPT1", "not bench files"
    design, p, state, valid_thr, ready_thr, spans = struct.unpack_from("<6I", stim, 8)
    # Format 2 puts its model's description before the records and says where they start.
    (records_at,) = struct.unpack_from("<I", stim, 56) if stim[:8] == b"SSBSTIM2" else (64,)
    (record,) = struct.unpack_from("<I", expect, 12)
    limit = int(os.environ.get("BENCH_SPANS", "0"))
    if 0 < limit < spans:
        spans = limit
    recs = [struct.unpack_from("<8I", stim, records_at + 32 * k) for k in range(spans)]
    return design, p, Traffic(state, valid_thr, ready_thr), recs, expect[24:], record


@cocotb.test()
async def bench(dut):
    design, p, traffic, recs, expect, record = read_files()
    mask_bytes = (p + 7) // 8
    if design == 0:
        ports = [dut.in_x, dut.in_len, dut.in_i0, dut.in_di]
        byte_mask = [int.from_bytes(bytes(0xFF if m >> i & 1 else 0 for i in range(8)), "little") for m in range(256)]

        def check(k):
            """Pixels compared, or -1 on a mismatch."""
            r = expect[k * record : (k + 1) * record]
            (x_last,) = struct.unpack_from("<I", r, 0)
            want_mask = int.from_bytes(r[4 : 4 + mask_bytes], "little")
            want_pix = int.from_bytes(r[4 + mask_bytes : 4 + mask_bytes + p], "little")
            if int(dut.out_x.value) != x_last & 0x7FFFFFFF or int(dut.out_last.value) != x_last >> 31:
                return -1
            if int(dut.out_mask.value) != want_mask:
                return -1
            lanes = 0
            for b in range(mask_bytes):
                lanes |= byte_mask[want_mask >> (8 * b) & 0xFF] << (64 * b)
            if (int(dut.out_pix.value) ^ want_pix) & lanes:
                return -1
            return bin(want_mask).count("1")

    else:
        ports = [dut.in_c, dut.in_n, dut.in_theta0, dut.in_dtheta, dut.in_len]

        def check(k):
            spec, err, last = struct.unpack_from("<HBB", expect, 4 * k)
            got = (int(dut.out_spec.value), int(dut.out_err.value), int(dut.out_last.value))
            return 1 if got == (spec, err, last) else -1

    # The RTL has no timescale: a period of 2 simulator steps.
    cocotb.start_soon(Clock(dut.clk, 2, units="step").start())
    # Two clocks of reset with the inputs idle, as the harness.
    dut.rst.value = 1
    dut.in_valid.value = 0
    dut.out_ready.value = 0
    for _ in range(2):
        await FallingEdge(dut.clk)
    dut.rst.value = 0

    clocks = pixels = checked = owed = mismatches = idle = drain = 0
    nxt, offering = 0, False
    start, cpu_start = time.perf_counter(), time.thread_time()
    while True:
        if nxt == len(recs) and checked == owed:
            if drain == DRAIN_CLOCKS:
                break
            drain += 1
        await FallingEdge(dut.clk)
        offer, ready = traffic.clock()
        if not offering and nxt < len(recs):
            offering = offer
            if offering:
                for port, value in zip(ports, recs[nxt]):
                    port.value = value
        dut.in_valid.value = int(offering)
        dut.out_ready.value = int(ready)
        await ReadOnly()
        clocks += 1
        progress = False
        if ready and int(dut.out_valid.value):
            progress = True
            if checked < owed:
                n = check(checked)
                if n < 0:
                    mismatches += 1
                    if mismatches <= 10:
                        dut._log.error("MISMATCH output %d (clock %d)", checked, clocks)
                else:
                    pixels += n
                checked += 1
            else:
                mismatches += 1
                dut._log.error("MISMATCH output with nothing outstanding (clock %d)", clocks)
        if offering and int(dut.in_ready.value):
            progress = True
            owed += recs[nxt][5]
            nxt += 1
            offering = False
        idle = 0 if progress else idle + 1
        if idle > STALL_LIMIT:
            mismatches += 1
            dut._log.error("MISMATCH no transfer for %d clocks", STALL_LIMIT)
            break
    secs, cpu = time.perf_counter() - start, time.thread_time() - cpu_start
    model = f"segment_shader_p{p}" if design == 0 else "specular_unit"
    line = (
        f"RESULT impl=cocotb model={model} spans={nxt} clocks={clocks} pixels={pixels} "
        f"secs={secs:.6f} cpu={cpu:.6f} mismatches={mismatches}"
    )
    dut._log.info(line)
    with open(os.environ["BENCH_RESULT"], "w") as f:
        f.write(line + "\n")
    assert mismatches == 0, f"{mismatches} mismatches"
