"""Phase detection: accuracy on real motion capture, and speed, each method against the seed's
rule (``seed-7.2.5``, dissertation section 7.2.5) measured in the same run.

- KTH sample (github KTH-RPL/handovers_dataset, one_saved_handover_New/handover_sample; found
  through GAZEBOT_KTH_DATA or /work/data/kth, skipped when absent): every method's transfer
  start and end against the force truth (both grips loaded / the giver's grip lets go), and
  the online detection latency of the transfer.
- Offline throughput: recordings segmented per second over a synthetic set (100 Hz, ~8 s).
- Online cost: median time of one ``PhaseDetector.update`` per sample.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.common import Result
from benchmarks.kth_data import RATE, force_truth, kth_dir
from gazebot.phases import METHODS, PhaseConfig, PhaseDetector, Trajectory, run_online, segment
from gazebot.phases.synthetic import synthetic_set
from gazebot.types import EventKind, Phase

SEED = "seed-7.2.5"


def _interleaved(a, b, repeat: int) -> tuple[float, float]:
    """Median wall times (s) of ``a()`` and ``b()``, run alternately after one warm-up each."""
    a(), b()
    ta, tb = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        a()
        ta.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        b()
        tb.append(time.perf_counter() - t0)
    return float(np.median(ta)), float(np.median(tb))


def _kth_trajectory() -> tuple[Trajectory, float, float] | None:
    from gazebot.recordings import PointNames, load_recording

    folder = kth_dir()
    if folder is None:
        return None
    names = PointNames("giver_RHand", "taker_RHand", "giver_head")
    traj = load_recording(folder, names, rate=RATE).trajectory
    t0, t1 = force_truth(folder)
    return traj, t0, t1


def _kth_results() -> list[Result]:
    found = _kth_trajectory()
    if found is None:
        return [Result("KTH sample", float("nan"), None, "", note="absent: set GAZEBOT_KTH_DATA")]
    traj, t0, t1 = found
    out = []
    errs = {}
    for m in METHODS:
        c = PhaseConfig(method=m)
        tr = [s for s in segment(traj, c) if s.phase is Phase.TRANSFER]
        ev = [e for e in run_online(traj, c).events if e.kind is EventKind.TRANSFER_STARTED]
        es = (tr[0].start - t0) * 1e3 if tr else float("nan")
        ee = (tr[0].end - t1) * 1e3 if tr else float("nan")
        lat = (ev[0].detected_at - t0) * 1e3 if ev else float("nan")
        errs[m] = (es, ee, lat)
    ps, pe, pl = errs[SEED]
    for m, (es, ee, lat) in errs.items():
        out.append(
            Result(
                f"KTH transfer start error, {m}",
                abs(es),
                abs(ps),
                "ms",
                SEED,
                note=(
                    f"signed start {es:+.0f} ms, end {ee:+.0f} ms; online detected {lat:+.0f} ms "
                    f"after the force truth (truth {t0:.3f}-{t1:.3f} s, 120 Hz)"
                ),
            )
        )
    return out


def run() -> list[Result]:
    results = _kth_results()
    cases = synthetic_set(12, seed=7, rate=100.0, handovers=1)
    trajs = [c.trajectory for c in cases]
    seed_cfg = PhaseConfig(method=SEED)
    for m in METHODS:
        if m == SEED:
            continue
        cfg = PhaseConfig(method=m)
        t_ours, t_peer = _interleaved(
            lambda cfg=cfg: [segment(tr, cfg) for tr in trajs],
            lambda: [segment(tr, seed_cfg) for tr in trajs],
            repeat=7,
        )
        results.append(
            Result(
                f"offline segmentation, {m}",
                len(trajs) / t_ours,
                len(trajs) / t_peer,
                "recordings/s",
                SEED,
                higher_is_better=True,
                note="12 synthetic recordings, 100 Hz, ~8 s each",
            )
        )
    frames = cases[0].trajectory.frames()

    def one_pass(cfg):
        def run_pass() -> None:
            det = PhaseDetector(cfg)
            for f in frames:
                det.update(f)

        return run_pass

    ours, peer = _interleaved(one_pass(PhaseConfig()), one_pass(seed_cfg), repeat=5)
    results.append(
        Result(
            "online update per sample, gazebot",
            ours / len(frames) * 1e6,
            peer / len(frames) * 1e6,
            "us",
            f"{SEED} run online the same way",
            note=(
                f"{len(frames)} samples at 100 Hz; re-analysis every online_period "
                f"({PhaseConfig().online_period * 1e3:.0f} ms) over online_window"
            ),
        )
    )
    return results
