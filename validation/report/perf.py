# The performance parts of the report: several `rayaudit bench --json` runs
# combined into one figure per row with its spread, the machine they ran on,
# and the drawing rules every performance chart follows (ratios on a log axis
# centred on 1x with bars from 1x, whole axes, labels placed so they do not
# overlap, the run's mode and repetitions stamped on the chart). Design and
# measured steadiness: bench/README.md.
import math
import os
import subprocess

import matplotlib
import matplotlib.ticker
import numpy as np

SLOW_FACTOR = 1.15  # a run whose calibration took this much longer than the fastest run's is slow
DISAGREE = 0.10     # run medians further apart than this share of the median (and the pooled IQR) disagree

# Google Benchmark's own keys of a row; every other number is a figure.
GB_KEYS = {"name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
           "repetition_index", "threads", "iterations", "time_unit", "error_occurred", "error_message",
           "aggregate_name", "aggregate_unit", "label", "skipped"}


def metric_of(name):
    """The figure each group's charts draw, and which way is better."""
    g = name.split("/", 1)[0]
    return {"kernel": ("ns_per_test", "lower"), "scene": ("Mrays_per_s", "higher"), "peer": ("ratio", "higher"),
            "obj": ("MB_per_s", "higher"), "oracle": ("cases/s", "higher")}.get(g, ("real_time", "lower"))


def five(vals):
    v = np.asarray(vals, dtype=float)
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return {"median": float(med), "q1": float(q1), "q3": float(q3), "min": float(v.min()), "max": float(v.max()),
            "n": int(v.size)}


def _figures(row):
    return {k: float(v) for k, v in row.items()
            if k not in GB_KEYS and not k.startswith("rayaudit_") and isinstance(v, (int, float))
            and not isinstance(v, bool) and math.isfinite(v)}


def _one_file(path, bench):
    """name -> {figure: [values of the good repetitions]}, and the run's facts."""
    ra = bench.get("rayaudit") or {}
    reps, aggs = {}, {}
    for b in bench.get("benchmarks", []):
        if b.get("error_occurred"):
            continue
        name = b.get("run_name") or b["name"]
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                aggs[name] = b
            continue
        reps.setdefault(name, []).append(b)
    rows = {}
    for name, rs in reps.items():
        good = [r for r in rs if not r.get("rayaudit_slow_phase")] or rs
        vals = {}
        for r in good:
            for k, v in _figures(r).items():
                vals.setdefault(k, []).append(v)
        rows[name] = {"values": vals, "slow": len(rs) - len([r for r in rs if not r.get("rayaudit_slow_phase")]),
                      "reps": len(rs)}
    for name, a in aggs.items():  # a Google Benchmark JSON of aggregates only
        if name not in rows:
            rows[name] = {"values": {k: [v] for k, v in _figures(a).items()}, "slow": 0, "reps": a.get("repetitions", 1)}
    flagged = {e["name"]: e["flagged"] for e in ra.get("rows", []) if e.get("flagged")}
    cal = [s["us"] for s in ra.get("calibration", {}).get("samples", [])]
    return {
        "file": path,
        "mode": ra.get("mode") or ("quick?" if not ra else "full"),
        "rounds": ra.get("rounds"),
        "runs": ra.get("runs", 1),
        "calibration_us": float(np.median(cal)) if cal else None,
        "calibration_samples": len(cal),
        "machine": ra.get("machine"),
        "steal_pct": ra.get("steal_pct"),
        "flagged_rows": flagged,
        "context": bench.get("context", {}),
    }, rows


def combine(paths_and_benches):
    """Several bench JSONs as one: each row's figure is the median of the
    runs' medians (runs marked slow left out while others remain); its spread
    the quartiles and range of every good repetition of those runs."""
    runs, per_run = [], []
    for path, b in paths_and_benches:
        info, rows = _one_file(path, b)
        runs.append(info)
        per_run.append(rows)
    cals = [r["calibration_us"] for r in runs if r["calibration_us"]]
    fastest = min(cals) if cals else None
    for r in runs:
        r["slow"] = bool(fastest and r["calibration_us"] and r["calibration_us"] > SLOW_FACTOR * fastest)
        r["calibration_vs_fastest"] = (r["calibration_us"] / fastest) if fastest and r["calibration_us"] else None
    used = [i for i, r in enumerate(runs) if not r["slow"]] or list(range(len(runs)))
    names = list(dict.fromkeys(n for rows in per_run for n in rows))
    out = {}
    for name in names:
        metric, better = metric_of(name)
        present = [i for i in used if name in per_run[i]] or [i for i in range(len(runs)) if name in per_run[i]]
        row, spread = {}, {}
        keys = list(dict.fromkeys(k for i in present for k in per_run[i][name]["values"]))
        for k in keys:
            medians = [float(np.median(per_run[i][name]["values"][k])) for i in present if k in per_run[i][name]["values"]]
            pooled = [v for i in present for v in per_run[i][name]["values"].get(k, [])]
            row[k] = float(np.median(medians))
            spread[k] = five(pooled) | {"median": row[k], "run_medians": medians}
        flags = []
        left_out = [runs[i]["file"] for i in range(len(runs)) if i not in present and name in per_run[i]]
        if left_out:
            flags.append("left out slow run(s): " + ", ".join(os.path.basename(f) for f in left_out))
        for i in present:
            f = runs[i]["flagged_rows"].get(name)
            if f:
                flags.append(f"{os.path.basename(runs[i]['file'])}: {f}")
        s = spread.get(metric)
        if s and len(s["run_medians"]) >= 2 and s["median"]:
            lo, hi = min(s["run_medians"]), max(s["run_medians"])
            if hi - lo > max(DISAGREE * abs(s["median"]), s["q3"] - s["q1"]):
                flags.append(f"runs disagree: their medians span {100 * (hi - lo) / abs(s['median']):.0f}% of the median")
        row["_spread"] = spread
        row["_metric"], row["_better"] = metric, better
        row["_flagged"] = "; ".join(flags)
        row["_reps"] = sum(per_run[i][name]["reps"] for i in present)
        out[name] = row
    return {"runs": runs, "rows": out, "used_runs": used}


def mode_text(bc):
    """'quick mode, 3 repetitions x 2 runs (interleaved)'."""
    runs = bc["runs"]
    modes = sorted({r["mode"] for r in runs})
    reps = sorted({r["rounds"] for r in runs if r["rounds"]})
    total = sum(r["runs"] or 1 for r in runs)
    rep = (f"{reps[0]} repetitions" if len(reps) == 1 else
           "repetitions " + "/".join(map(str, reps)) if reps else "repetitions not recorded")
    return f"{'/'.join(modes)} mode, {rep} x {total} run(s), interleaved"


# ------------------------------------------------------------------ machine --


def _run(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def local_machine():
    """The same facts rayaudit-bench records, for a report without them."""
    model, fms, hv, cores = "", ["", "", ""], False, 0
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                k, _, v = line.partition(":")
                k, v = k.strip(), v.strip()
                if k == "processor":
                    cores += 1
                elif k == "model name" and not model:
                    model = v
                elif k == "cpu family" and not fms[0]:
                    fms[0] = v
                elif k == "model" and not fms[1]:
                    fms[1] = v
                elif k == "stepping" and not fms[2]:
                    fms[2] = v
                elif k == "flags" and "hypervisor" in v.split():
                    hv = True
    except OSError:
        pass
    virt = _run(["systemd-detect-virt"])
    if not virt and os.path.exists("/sys/hypervisor/type"):
        with open("/sys/hypervisor/type") as f:
            virt = f.read().strip()
    return {"cpu_model": model, "cpu_family_model_stepping": "/".join(fms), "cores": cores or os.cpu_count(),
            "hypervisor_flag": hv,
            "virtualization": virt or ("virtual machine (hypervisor flag)" if hv else "none detected")}


def machine_line(m, steal=None):
    """'AMD EPYC (family 25 model 1 stepping 1), 2 cores; virtual: ...'."""
    fms = (m.get("cpu_family_model_stepping") or "").split("/")
    ident = f" (family {fms[0]}, model {fms[1]}, stepping {fms[2]})" if len(fms) == 3 and all(fms) else ""
    virt = m.get("virtualization") or "none detected"
    parts = [f"{m.get('cpu_model') or 'unknown CPU'}{ident}, {m.get('cores')} cores"]
    shared = []
    if virt not in ("none", "none detected"):
        shared.append(f"runs in {virt}")
    if m.get("hypervisor_flag"):
        shared.append("the CPU reports a hypervisor (a virtual machine: cores may be shared with other guests)")
    parts.append("virtual/shared: " + ("; ".join(shared) if shared else "no sign of virtualisation"))
    if steal is not None:
        parts.append(f"CPU time stolen by the hypervisor during the bench: {steal:.1f}%")
    return "; ".join(parts)


def short_machine(m):
    virt = m.get("virtualization") or ""
    tag = "shared VM" if m.get("hypervisor_flag") else ("container" if virt not in ("", "none", "none detected") else "")
    return f"{m.get('cpu_model') or 'CPU?'}, {m.get('cores')} cores" + (f", {tag}" if tag else "")


# ---------------------------------------------------------- drawing rules --


def stamp(fig, text):
    """The run's mode, repetitions, rays and machine, on the chart itself."""
    fig.suptitle(text, fontsize=7, color="#444", x=0.01, ha="left")


def times_label(v):
    """0.5 -> '0.5x', 1000 -> '1000x' (never '1e+03x')."""
    if v >= 1:
        return f"{v:.0f}x" if abs(v - round(v)) < 1e-9 else f"{v:.3g}x"
    return f"{v:.3g}x"


def ratio_text(r):
    """Three significant digits: 1.006 -> '1.01x', 0.906 -> '0.906x'."""
    return f"{r:.3g}x"


def ratio_axis(ax, values, axis="x"):
    """A log axis centred on 1x holding every value (and error bar end),
    with ticks 1-2-5 labelled as plain multiples; returns the limits."""
    vals = [v for v in values if v and v > 0 and math.isfinite(v)]
    span = max([abs(math.log10(v)) for v in vals] + [math.log10(2)]) * 1.15
    lo, hi = 10 ** -span, 10 ** span
    set_scale = ax.set_xscale if axis == "x" else ax.set_yscale
    set_lim = ax.set_xlim if axis == "x" else ax.set_ylim
    set_scale("log")
    set_lim(lo, hi)
    ticks = [m * 10 ** e for e in range(-6, 7) for m in (1, 2, 5) if lo <= m * 10 ** e <= hi]
    if len(ticks) > 9:
        ticks = [t for t in ticks if abs(math.log10(t) - round(math.log10(t))) < 1e-9]
    (ax.set_xticks if axis == "x" else ax.set_yticks)(ticks, [times_label(t) for t in ticks])
    (ax.xaxis if axis == "x" else ax.yaxis).set_minor_locator(matplotlib.ticker.NullLocator())
    (ax.axvline if axis == "x" else ax.axhline)(1, color="k", lw=1)
    return [lo, hi]


def ratio_error(row_a, row_b, key):
    """The spread of a / b from the two rows' quartiles: (low, high)."""
    sa, sb = row_a["_spread"].get(key), row_b["_spread"].get(key)
    if not sa or not sb or sb["q1"] <= 0 or sb["q3"] <= 0:
        return None
    return sa["q1"] / sb["q3"], sa["q3"] / sb["q1"]


def place_labels(fig, ax, texts, points_px=()):
    """Moves each annotation (made with textcoords='offset points') to the
    first of a fixed ring of offsets where it overlaps no label placed before
    it, nor a marker; deterministic (the points' order). Returns the number
    of overlapping pairs left (0 when every label found room)."""
    r = _renderer(fig)
    offsets = [(4, 3), (4, -9), (-4, 3), (-4, -9), (8, 10), (8, -16), (-8, 10), (-8, -16), (14, 0), (-14, 0),
               (0, 14), (0, -20), (16, 18), (16, -24), (-16, 18), (-16, -24), (24, 4), (-24, 4)]
    placed = []
    markers = [matplotlib.transforms.Bbox.from_bounds(x - 4, y - 4, 8, 8) for x, y in points_px]
    for t in texts:
        best = None
        for dx, dy in offsets:
            t.set_position((dx, dy))
            t.set_horizontalalignment("left" if dx >= 0 else "right")
            bb = t.get_window_extent(r).expanded(1.02, 1.1)
            hits = sum(bb.overlaps(o) for o in placed) + sum(bb.overlaps(m) for m in markers)
            if best is None or hits < best[0]:
                best = (hits, dx, dy)
            if hits == 0:
                break
        _, dx, dy = best
        t.set_position((dx, dy))
        t.set_horizontalalignment("left" if dx >= 0 else "right")
        if (dx, dy) != offsets[0]:
            t.arrow_patch = None
        placed.append(t.get_window_extent(r).expanded(1.02, 1.1))
    return count_overlaps(fig, texts)


def _renderer(fig):
    """A renderer with the layout applied (the SVG canvas has none of its own)."""
    fig.draw_without_rendering()
    try:
        return fig._get_renderer()
    except AttributeError:
        return fig.canvas.get_renderer()


def count_overlaps(fig, texts):
    r = _renderer(fig)
    boxes = [t.get_window_extent(r) for t in texts if t.get_visible()]
    return int(sum(bool(boxes[i].overlaps(boxes[j])) for i in range(len(boxes)) for j in range(i + 1, len(boxes))))


def axis_facts(ax, chart_id, ratio=None, labels=None):
    """What a reader checks on a chart, for report.json (and its tests)."""
    return {"chart": chart_id, "title": ax.get_title(), "xscale": ax.get_xscale(), "yscale": ax.get_yscale(),
            "xlim": [float(v) for v in ax.get_xlim()], "ylim": [float(v) for v in ax.get_ylim()],
            "ratio_axis": ratio, "label_overlaps": labels}


# ----------------------------------------------------- kernel and hit rate --


def kernel_hit_rate(bc):
    """method -> precision -> [(hit %, five-number ns)] of the nocull,
    no-back-face kernel rows (Löfstedt & Akenine-Möller's sweep: the cost of
    a test depends on how often it hits, as early exits are taken or not)."""
    out = {}
    for name, row in bc["rows"].items():
        parts = name.split("/")
        if len(parts) < 6 or parts[0] != "kernel" or parts[3] != "nocull":
            continue
        keys = dict(p.split("=", 1) for p in parts[4:] if "=" in p)
        if keys.get("back", "0") != "0" or "hit" not in keys or "ns_per_test" not in row:
            continue
        out.setdefault(parts[1], {}).setdefault(parts[2], []).append((float(keys["hit"]), row["_spread"]["ns_per_test"]))
    for m in out.values():
        for p in m.values():
            p.sort(key=lambda x: x[0])
    return out


def chart_kernel_hit_rate(plt, khr, methods, stamp_text):
    """ns per test against hit rate, one panel per precision, every method a
    line with its interquartile range as error bars; y from 0."""
    precisions = [p for p in ("float", "double") if any(p in m for m in khr.values())]
    kinds = {}
    for name in khr:
        kinds.setdefault(methods.by_name.get(name, {}).get("kind", "triangle"), []).append(name)
    fig, axes = plt.subplots(len(kinds), len(precisions), figsize=(5.6 * len(precisions), 3.4 * len(kinds)),
                             squeeze=False)
    facts = []
    top = max(s["max"] for m in khr.values() for pts in m.values() for _, s in pts)
    for i, (kind, names) in enumerate(sorted(kinds.items())):
        for j, prec in enumerate(precisions):
            ax = axes[i][j]
            for n in names:
                pts = khr[n].get(prec)
                if not pts:
                    continue
                x = [h for h, _ in pts]
                y = [s["median"] for _, s in pts]
                # The figure is the median of the runs' medians, the quartiles
                # are of every repetition pooled: with runs of unequal length
                # the figure can lie outside them (the bar then starts at it).
                err = [[max(s["median"] - s["q1"], 0) for _, s in pts], [max(s["q3"] - s["median"], 0) for _, s in pts]]
                ax.errorbar(x, y, yerr=err, marker="o", ms=3, capsize=2, lw=1.2,
                            ls="--" if methods.is_document(n) else "-", color=methods.colour.get(n, "k"),
                            label=methods.label(n))
                # min-max as a faint band: the whole range over repetitions and runs
                ax.fill_between(x, [s["min"] for _, s in pts], [s["max"] for _, s in pts],
                                color=methods.colour.get(n, "k"), alpha=0.08, lw=0)
            ax.set_xlim(-5, 105)
            ax.set_ylim(0, top * 1.08)
            ax.set_xticks([0, 10, 50, 90, 100])
            ax.set_xlabel("rays that hit (%)")
            ax.set_ylabel("ns per test (median; bars: quartiles)")
            ax.set_title(f"{kind} tests, {prec}: cost against hit rate")
            facts.append(axis_facts(ax, f"kernel_hit_rate/{kind}/{prec}"))
        axes[i][-1].legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1))
    stamp(fig, stamp_text)
    return fig, facts


# ------------------------------------------------------------- the runs ----


def spread_table_html(bc, esc, fnum):
    """The runs (calibration, slow or not) and the rows flagged."""
    h = ['<table><tr><th class="l">bench JSON</th><th class="l">mode</th><th>repetitions</th>'
         '<th>calibration (median &micro;s)</th><th>over the fastest run</th><th class="l">verdict</th></tr>']
    for i, r in enumerate(bc["runs"]):
        verdict = ('<span class="bad">slow phase: left out of the medians</span>' if r["slow"] and
                   i not in bc["used_runs"] else '<span class="bad">slow</span>' if r["slow"] else
                   '<span class="ok">normal speed</span>' if r["calibration_us"] else
                   '<span class="warn">no calibration recorded</span>')
        vs = r["calibration_vs_fastest"]
        h.append(f'<tr><td class="l">{esc(os.path.basename(r["file"]))}</td><td class="l">{esc(r["mode"])}</td>'
                 f'<td>{r["rounds"] or "-"}</td><td>{fnum(r["calibration_us"])}</td>'
                 f'<td>{"-" if vs is None else f"{100 * (vs - 1):+.1f}%"}</td><td class="l">{verdict}</td></tr>')
    h.append("</table>")
    flagged = [(n, r["_flagged"]) for n, r in bc["rows"].items() if r["_flagged"]]
    rel = [(r["_spread"][r["_metric"]]["q3"] - r["_spread"][r["_metric"]]["q1"]) / abs(r["_spread"][r["_metric"]]["median"])
           for r in bc["rows"].values() if r["_metric"] in r["_spread"] and r["_spread"][r["_metric"]]["median"]]
    if rel:
        h.append(f'<p class="cap">Spread of the {len(rel)} rows: interquartile range over the median, median '
                 f'{100 * float(np.median(rel)):.1f}%, 90th percentile {100 * float(np.percentile(rel, 90)):.1f}%, '
                 f'worst {100 * max(rel):.1f}%.</p>')
    if flagged:
        h.append(f'<p class="notice">{len(flagged)} row(s) flagged; their figures are less sure than their bars '
                 'show:</p><table><tr><th class="l">row</th><th class="l">why</th></tr>')
        for n, why in flagged[:40]:
            h.append(f'<tr><td class="l">{esc(n)}</td><td class="l">{esc(why)}</td></tr>')
        if len(flagged) > 40:
            h.append(f'<tr><td class="l" colspan="2">... {len(flagged) - 40} more (report.json)</td></tr>')
        h.append("</table>")
    else:
        h.append('<p class="ok">No row flagged: every row\'s runs agree within their spread.</p>')
    return "\n".join(h)
