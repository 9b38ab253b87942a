#!/usr/bin/env python3
"""Host-rate sweep: the proxy's force error against the host CPU it costs.

`fissure bench proxy` from Python: one closed-loop lockstep session with the host refreshing the
contact proxy every rt tick is the oracle; the same device trajectory is replayed with the host at
each lower rate, and the rendered contact force is compared with the oracle's (RMS and peak, % of
the oracle's peak force). The host's CPU time per simulated second is measured on this machine.
The benchmark keeps the soft body's collision sub-step at one rt period for every row (a slower
host takes more sub-steps per step, so only the proxy's refresh rate differs): the host CPU then
hardly falls with the rate — the sub-steps, not the proxy builds, are what the host pays for.

    PYTHONPATH=build/python python3 examples/python/host_rate_sweep.py [--quick]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fissure  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", default="spatula-sphere")
    parser.add_argument("--quick", action="store_true", help="three rates, the first 1.2 s of the hand script (CI)")
    parser.add_argument("--out", default="out/python/host_rate_sweep.png", help="PNG to write")
    args = parser.parse_args(argv)
    rates = [1000.0, 250.0, 50.0] if args.quick else [1000.0, 500.0, 250.0, 100.0, 50.0]
    result = fissure.bench_proxy(scene=args.scene, rt_rate_hz=2000.0, host_rates_hz=rates,
                                 duration_s=1.2 if args.quick else 0.0, settle_s=0.5 if args.quick else 1.0)
    rows = result["rows"]
    oracle = result["oracle"]
    for r in rows:
        print(f"host {r['host_hz']:6.0f} Hz  rms {r['rms_error_pct']:6.3f} %  peak {r['peak_error_pct']:6.3f} %  "
              f"host CPU {r['host_cpu_s_per_s'] * 1e3:7.2f} ms/s")

    fig, (ax_cost, ax_rate) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    cpu_ms = [r["host_cpu_s_per_s"] * 1e3 for r in rows]
    ax_cost.plot(cpu_ms, [r["rms_error_pct"] for r in rows], "o-", label="RMS")
    ax_cost.plot(cpu_ms, [r["peak_error_pct"] for r in rows], "s--", label="peak")
    for r, x in zip(rows, cpu_ms):
        ax_cost.annotate(f"{r['host_hz']:.0f} Hz", (x, r["rms_error_pct"]), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax_cost.axvline(oracle["host_cpu_s_per_s"] * 1e3, color="grey", ls=":", lw=0.8, label=f"oracle ({oracle['host_hz']:.0f} Hz)")
    ax_cost.set_xlabel("host CPU per simulated second [ms/s]")
    ax_cost.set_ylabel("rendered force error [% of oracle peak]")
    ax_cost.legend()
    ax_rate.plot([r["host_hz"] for r in rows], [r["rms_error_pct"] for r in rows], "o-", label="RMS error")
    ax_rate.set_xscale("log")
    ax_rate.set_yscale("log")
    ax_rate.set_xlabel("host rate [Hz]")
    ax_rate.set_ylabel("RMS force error [% of oracle peak]")
    targets = result.get("targets", {})
    if "rms_error_pct_at_100_hz" in targets:
        ax_rate.plot([100.0], [targets["rms_error_pct_at_100_hz"]], "rv", label="target at 100 Hz")
    if "rms_error_pct_at_1000_hz" in targets:
        ax_rate.plot([1000.0], [targets["rms_error_pct_at_1000_hz"]], "r^", label="target at 1 kHz")
    ax_rate.legend()
    for ax in (ax_cost, ax_rate):
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"Proxy error against host rate and CPU ({args.scene}, rt {result['oracle']['host_hz']:.0f} Hz)")
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    return result


if __name__ == "__main__":
    main()
