"""Builds and runs bench/cocotb/test_bench.py under Icarus Verilog with cocotb's Python runner.

    python run.py build --top TOP --build-dir DIR [--param NAME=VALUE ...] --source FILE ...
    python run.py test  --top TOP --build-dir DIR

`build` compiles with iverilog (only when a source or parameter changed); `test` runs the
simulation with the BENCH_* variables test_bench.py reads.
"""

import argparse
import hashlib
import os
import sys
import warnings
from pathlib import Path

warnings.filterwarnings("ignore", message="Python runners")
from cocotb.runner import get_results, get_runner  # noqa: E402

HERE = Path(__file__).resolve().parent


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("action", choices=["build", "test"])
    ap.add_argument("--top", required=True)
    ap.add_argument("--build-dir", required=True, type=Path)
    ap.add_argument("--param", action="append", default=[])
    ap.add_argument("--source", dest="sources", action="append", default=[], type=Path)
    args = ap.parse_args()
    runner = get_runner("icarus")
    if args.action == "build":
        params = dict(p.split("=", 1) for p in args.param)
        key = hashlib.sha256()
        for s in args.sources:
            key.update(s.read_bytes())
        key.update(repr(sorted(params.items())).encode())
        stamp = args.build_dir / "build.key"
        if stamp.exists() and stamp.read_text() == key.hexdigest() and (args.build_dir / "sim.vvp").exists():
            print("cocotb: up to date")
            return
        runner.build(
            verilog_sources=[str(s) for s in args.sources],
            hdl_toplevel=args.top,
            parameters=params,
            build_dir=str(args.build_dir),
            always=True,
        )
        stamp.write_text(key.hexdigest())
    else:
        sys.path.insert(0, str(HERE))
        # The simulation runs in the build folder: the files' paths are made absolute first, so
        # paths relative to where this was called from work.
        for k in ("BENCH_STIM", "BENCH_EXPECT", "BENCH_RESULT"):
            if k in os.environ:
                os.environ[k] = str(Path(os.environ[k]).resolve())
        results = runner.test(
            hdl_toplevel=args.top,
            hdl_toplevel_lang="verilog",
            test_module="test_bench",
            build_dir=str(args.build_dir),
            test_dir=str(args.build_dir),
            extra_env={"PYTHONPATH": str(HERE) + os.pathsep + os.environ.get("PYTHONPATH", "")},
        )
        # The runner returns normally when the test fails; a failed bench is a failed command.
        _, failed = get_results(results)
        if failed:
            sys.exit(f"cocotb: {failed} test(s) failed (see {args.build_dir}/results.xml)")


if __name__ == "__main__":
    main()
