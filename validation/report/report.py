#!/usr/bin/python3
# The report page: charts drawn by matplotlib as inline SVG, thumbnails
# as data: URIs, one self-contained index.html and the report.json behind it.
#
# Run by `rayaudit report` (cli/cmd_report.cpp) with /usr/bin/python3, which has
# Debian's matplotlib; that command has already checked every input's shape.
# What only this script can find (an image PIL cannot read or too large to
# show, anything unforeseen) is one line naming the input and exit 2, never a
# traceback; rayaudit report then exits 2 without a line of its own.
import base64
import datetime
import glob
import html
import io
import json
import math
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image, ImageDraw  # noqa: E402

import perf  # noqa: E402  (the performance parts: spread, machine, drawing rules)
import peer_subjects  # noqa: E402  (beside this file: peers marked in sections 1 and 2)
import tracers_report  # noqa: E402  (the whole-tracer section, beside this file)

plt.rcParams.update({
    "svg.fonttype": "none",  # text stays text: smaller and searchable
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "figure.dpi": 96,
    "figure.constrained_layout.use": True,
})

THUMB = 160  # largest side of an image thumbnail, pixels
# Images are decoded whole before shrinking: beyond this many pixels (4096 x
# 4096, ~50 MB as RGB) one is refused by name rather than decoded, so memory
# stays in the hundreds of MB; PIL's own guard is replaced by this one
# (its warning and its error were several lines).
MAX_IMAGE_PIXELS = 4096 * 4096
Image.MAX_IMAGE_PIXELS = None

# The input being read, named by the one-line error if something in it
# cannot be used (tracebacks).
current_input = ["(report context)"]


class BadInput(Exception):
    """A message naming its file, printed as is."""


def load_json(path):
    current_input[0] = path
    # utf-8-sig: a byte-order mark is skipped, as the C++ checks do.
    with open(path, encoding="utf-8-sig") as f:
        return json.load(f)
ZERO_FLOOR = 1e-5  # where "0 %" is drawn on a log axis

# The run's mode, repetitions and machine, stamped on every performance chart
# (set by main), and what each chart's axes show (written to report.json).
STAMP = [""]
CHART_FACTS = []

# ------------------------------------------------------------------ helpers --


def svg_of(fig):
    buf = io.StringIO()
    fig.savefig(buf, format="svg", bbox_inches="tight")
    plt.close(fig)
    text = buf.getvalue()
    # Keep only the <svg> element (drop the XML prolog and DOCTYPE).
    return text[text.index("<svg"):]


def data_uri(path, max_side=THUMB, marks=()):
    """A PNG thumbnail as a data: URI; `marks` (x, y) pixels of the original
    are ringed, so a single differing pixel still shows after shrinking."""
    current_input[0] = path
    try:
        im = Image.open(path)
    except (OSError, SyntaxError, ValueError) as e:
        raise BadInput(f"{path}: not a readable image ({type(e).__name__})") from None
    w, h = im.size
    if w * h > MAX_IMAGE_PIXELS:
        raise BadInput(f"{path}: {w}x{h} is too large to show in the report (at most {MAX_IMAGE_PIXELS} pixels)")
    with im:
        try:
            im = im.convert("RGB")
        except (OSError, SyntaxError, ValueError) as e:
            raise BadInput(f"{path}: not a readable image ({e})") from None
        w0 = im.size[0]
        if max(im.size) > max_side:
            im.thumbnail((max_side, max_side), Image.NEAREST)
        if marks:
            draw = ImageDraw.Draw(im)
            k = im.size[0] / w0
            for x, y in marks:
                cx, cy = (x + 0.5) * k, (y + 0.5) * k
                draw.ellipse((cx - 5, cy - 5, cx + 5, cy + 5), outline=(255, 220, 0), width=2)
        buf = io.BytesIO()
        im.save(buf, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def esc(s):
    return html.escape(str(s))


def offset_label(v):
    """1 -> '1', 1000 -> '1e3', 1e7 -> '1e7'."""
    if v > 0 and v >= 1000 and 10 ** round(math.log10(v)) == v:
        return f"1e{round(math.log10(v))}"
    return f"{v:g}"


def fnum(v, digits=3):
    if v is None:
        return "-"
    if isinstance(v, float) and (math.isnan(v) or math.isinf(v)):
        return "-"
    if v == 0:
        return "0"
    a = abs(v)
    if a >= 1e5 or a < 1e-3:
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def sweep_number(label):
    try:
        return float(label)
    except ValueError:
        return None


# ------------------------------------------------------------------- inputs --


class Methods:
    """The registry as rayaudit reports it: colours, and which are the documents'.
    Subjects that are not the registry's (users' graded or API runs) get
    colours of their own and the label "(yours)" in every chart and legend."""

    USER_COLOURS = ["#e6007e", "#00a6a6", "#8c564b", "#6a3d9a", "#b15928", "#1f1f1f"]

    def __init__(self, methods):
        self.by_name = {m["name"]: m for m in methods}
        cmap = plt.get_cmap("tab10")
        tri = [m["name"] for m in methods if m["kind"] == "triangle"]
        sph = [m["name"] for m in methods if m["kind"] == "sphere"]
        self.colour = {}
        for i, n in enumerate(tri):
            self.colour[n] = cmap(i % 10)
        for i, n in enumerate(sph):
            self.colour[n] = cmap((i + 4) % 10)
        self.users = []

    def add_user(self, name):
        if name not in self.by_name and name not in self.users:
            self.colour[name] = self.USER_COLOURS[len(self.users) % len(self.USER_COLOURS)]
            self.users.append(name)

    def is_user(self, name):
        return name in self.users

    def is_document(self, name):
        m = self.by_name.get(name)
        return bool(m) and m["source"].startswith("seeds/")

    def label(self, name):
        return name + (" (doc)" if self.is_document(name) else "") + (" (yours)" if self.is_user(name) else "")


def bench_rows(bench):
    """name -> row: each figure the median over the runs (perf.combine), its
    spread under "_spread"."""
    return (bench or {}).get("rows", {})


def parse_bench_name(name):
    """'kernel/moller/float/nocull/hit=50/back=0/real_time' -> (['kernel', ...], {'hit': '50', ...})"""
    parts, keys = [], {}
    for p in name.split("/"):
        if "=" in p:
            k, v = p.split("=", 1)
            keys[k] = v
        elif ":" in p or p in ("real_time", "manual_time"):
            continue
        else:
            parts.append(p)
    return parts, keys


# ---------------------------------------------------------------- section 1 --


def speed_accuracy(audit, bench, methods, timings=None):
    rows = bench_rows(bench)
    ns = {}
    for name, b in rows.items():
        parts, keys = parse_bench_name(name)
        if parts[:1] == ["kernel"] and len(parts) >= 4 and parts[3] == "nocull" \
                and keys.get("hit") == "50" and keys.get("back", "0") == "0" and "ns_per_test" in b:
            ns[(parts[1], parts[2])] = (float(b["ns_per_test"]), b["_spread"].get("ns_per_test"), b["_flagged"])
    out = []
    for s in audit["subjects"]:
        t = s["totals"]
        groups = t.get("groups", 0)
        out.append({
            "subject": s["name"],
            "method": s["method"],
            "precision": s["precision"],
            "kind": s["kind"],
            "document_variant": methods.is_document(s["method"]),
            "ns_per_test": ns.get((s["method"], s["precision"]), ((timings or {}).get(s["name"]),))[0],
            "ns_spread": ns.get((s["method"], s["precision"]), (None, None))[1],
            "ns_flagged": ns.get((s["method"], s["precision"]), (None, None, ""))[2],
            "wrong_pct": t["wrong_pct"],
            "leaks": t.get("leaks", 0),
            "groups": groups,
            "leaks_per_million": (1e6 * t.get("leaks", 0) / groups) if groups else None,
            "tests": t["tests"],
            "worst": s.get("worst"),
        })
    return peer_subjects.annotate(out, methods, rows)


def pareto(points):
    """Indices of the points no other point beats on both x and y (lower is better)."""
    front = []
    for i, (x, y) in enumerate(points):
        if not any((x2 <= x and y2 <= y) and (x2 < x or y2 < y) for j, (x2, y2) in enumerate(points) if j != i):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def scatter_panel(ax, entries, methods, yfield, ylabel, title):
    pts = [(e["ns_per_test"], max(e[yfield], ZERO_FLOOR)) for e in entries]
    labels = []
    for e, (x, y) in zip(entries, pts):
        doc = e["document_variant"]
        c = methods.colour.get(e["method"], "k")
        sp = e.get("ns_spread")
        if sp:  # thin: min-max over repetitions and runs; thick: the quartiles
            ax.errorbar([x], [y], xerr=[[x - sp["min"]], [sp["max"] - x]], fmt="none", ecolor=c, lw=0.7, alpha=0.6)
            # (the figure, a median of run medians, may lie outside the pooled quartiles)
            ax.errorbar([x], [y], xerr=[[max(x - sp["q1"], 0)], [max(sp["q3"] - x, 0)]], fmt="none", ecolor=c, lw=2.2,
                        alpha=0.8)
        user = methods.is_user(e["method"])
        ax.scatter([x], [y], s=140 if user else 60,
                   marker="*" if user or e.get("peer") else "o" if e["precision"] == "float" else "s",
                   facecolors="none" if doc else [c], edgecolors=[c], linewidths=1.8, zorder=4 if user else 3)
        labels.append(ax.annotate(("doc: " if doc else "peer: " if e.get("peer") else "yours: " if user else "")
                                  + e["method"] + ("/f" if e["precision"] == "float" else "/d")
                                  + (" (!)" if e.get("ns_flagged") else ""),
                                  (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7.5 if user else 6.5,
                                  color=c, alpha=0.9, fontweight="bold" if user else "normal"))
    for name in dict.fromkeys(e["method"] for e in entries if methods.is_user(e["method"])):
        ax.scatter([], [], s=140, marker="*", color=methods.colour[name], label=methods.label(name))
    front = pareto(pts)
    if len(front) > 1:
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "k--", lw=1, alpha=0.6,
                label="Pareto front (nothing both faster and righter)")
    elif front:
        ax.scatter([pts[front[0]][0]], [pts[front[0]][1]], s=220, facecolors="none", edgecolors="k",
                   label="Pareto front")
    ax.set_yscale("log")
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.tick_params(axis="x", which="minor", labelsize=6.5)
    if any(e[yfield] == 0 for e in entries):  # zeros sit on a floor line, labelled
        ax.axhline(ZERO_FLOOR, color="g", lw=0.8, alpha=0.6)
        ax.text(ax.get_xlim()[0], ZERO_FLOOR, " 0 (none found)", color="g", fontsize=7, va="bottom")
    ax.set_xlabel("ns per ray/triangle test (log; kernel bench, 50% hits, 4096 pairs a row; left is faster;\n"
                  "thick bar: quartiles, thin: min-max over repetitions and runs; (!) flagged)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=7, frameon=False)
    return labels


def chart_speed_accuracy(entries, methods, have_bench):
    charts = []
    tri = [e for e in entries if e["kind"] == "triangle"]
    sph = [e for e in entries if e["kind"] == "sphere"]
    if have_bench:
        timed_tri = [e for e in tri if e["ns_per_test"] is not None]
        timed_sph = [e for e in sph if e["ns_per_test"] is not None]
        if timed_tri:
            fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
            labels0 = scatter_panel(axes[0], timed_tri, methods, "wrong_pct", "wrong % of tests (log; down is righter)",
                                    "Triangle methods: speed against wrong answers")
            leak = [e for e in timed_tri if e["leaks_per_million"] is not None]
            for e in leak:
                e["_lpm"] = e["leaks_per_million"]
            labels1 = scatter_panel(axes[1], [dict(e, wrong_pct=e["_lpm"]) for e in leak], methods, "wrong_pct",
                                    "watertight leaks per million group rays (log)", "Triangle methods: speed against leaks")
            for e in leak:
                del e["_lpm"]
            perf.stamp(fig, STAMP[0])
            for ax, labs, n in ((axes[0], labels0, "speed_wrong"), (axes[1], labels1, "speed_leaks")):
                CHART_FACTS.append(perf.axis_facts(ax, n, labels=perf.place_labels(fig, ax, labs)))
            charts.append((svg_of(fig), "Each point is a method x precision (circle float, square double, hollow = "
                           "a seed document's method as written). Down-left is better: the dashed line joins the "
                           "methods nothing else beats on both speed and correctness." +
                           (peer_subjects.CAPTION if any(e.get("peer") for e in timed_tri) else "")))
        if timed_sph:
            fig, ax = plt.subplots(figsize=(6, 4.4))
            labs = scatter_panel(ax, timed_sph, methods, "wrong_pct", "wrong % of tests (log)",
                                 "Sphere methods: speed against wrong answers")
            perf.stamp(fig, STAMP[0])
            CHART_FACTS.append(perf.axis_facts(ax, "speed_wrong_spheres", labels=perf.place_labels(fig, ax, labs)))
            charts.append((svg_of(fig), "Sphere methods over the sphere families (huge, tiny-far, near-origin, "
                           "refracted); same reading as above."))
    else:
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
        for ax, field, title in ((axes[0], "wrong_pct", "wrong % of tests"),
                                 (axes[1], "leaks_per_million", "leaks per million group rays")):
            es = [e for e in entries if e[field] is not None]
            ys = [max(e[field], ZERO_FLOOR) for e in es]
            cols = [methods.colour.get(e["method"], "k") for e in es]
            ax.barh(range(len(es)), ys, color=cols, hatch=None)
            for i, e in enumerate(es):
                if e["document_variant"]:
                    ax.barh([i], [ys[i]], color="none", edgecolor="k", hatch="//")
            ax.set_yticks(range(len(es)), [methods.label(e["method"]) + "/" + e["precision"] for e in es], fontsize=7)
            ax.set_xscale("log")
            ax.invert_yaxis()
            ax.set_xlabel(title + " (log; shorter is righter; 1e-5 means none)")
            ax.set_title(title + " (no benchmark given: no speed axis)")
        charts.append((svg_of(fig), "No benchmark given, so there is no speed axis: correctness only. Hatched bars "
                       "are the seed documents' methods as written."))
    return charts


# ---------------------------------------------------------------- section 2 --


def stability(audit):
    """family -> list of {sweep, x, subject, method, precision, wrong_pct, leaks, self_hit_pct}."""
    out = {}
    for c in audit["cells"]:
        s = c["stats"]
        method, prec = c["subject"].rsplit("/", 1)
        out.setdefault(c["family"], {"param": c["param"], "rows": []})["rows"].append({
            "sweep": c["sweep"],
            "subject": c["subject"],
            "method": method,
            "precision": prec,
            "tests": s["tests"],
            "wrong_pct": s["wrong_pct"],
            "leaks": s["leaks"],
            "groups": s["groups"],
            "double_hits": s["double_hits"],
            "spawned": s["spawned"],
            "self_hits": s["self_hits"],
            "self_hit_pct": (100.0 * s["self_hits"] / s["spawned"]) if s["spawned"] else None,
            # Refracted rays only (absent from audits before the family).
            "skipped_walls": s.get("skipped_walls", 0),
            "skip_pct": (100.0 * s.get("skipped_walls", 0) / s["spawned"]) if s["spawned"] else None,
        })
    return out


def refracted(audit):
    """The refracted family summed over the methods of each kind and precision: per strategy and scale, the
    spawned rays, self-hits and skipped far walls. [{kind, precision, strategy, scales: [{scale, spawned,
    self_hits, skipped_walls}]}]"""
    kind = {s["name"]: s.get("kind", "triangle") for s in audit.get("subjects", [])}
    rows = {}
    for c in audit["cells"]:
        if c["family"] != "refracted":
            continue
        s = c["stats"]
        strategy, _, scale = c["sweep"].partition("@")
        key = (kind.get(c["subject"], "triangle"), c["subject"].rsplit("/", 1)[1], strategy)
        row = rows.setdefault(key, {"kind": key[0], "precision": key[1], "strategy": strategy, "scales": {}})
        e = row["scales"].setdefault(scale, {"scale": scale, "spawned": 0, "self_hits": 0, "skipped_walls": 0})
        e["spawned"] += s["spawned"]
        e["self_hits"] += s["self_hits"]
        e["skipped_walls"] += s.get("skipped_walls", 0)
    return [dict(r, scales=list(r["scales"].values())) for r in rows.values()]


def refracted_table_html(rows):
    """Section 2's table of refracted rays: a row per kind, precision and strategy, a column per scale."""
    if not rows:
        return ""
    scales = list(dict.fromkeys(e["scale"] for r in rows for e in r["scales"]))
    h = ['<table class="grid"><tr><th class="l">kind</th><th class="l">precision</th><th class="l">strategy</th>' +
         "".join(f"<th>scale {esc(sc)}: self-hit % / skipped %</th>" for sc in scales) + "<th>spawned</th></tr>"]
    for r in rows:
        by = {e["scale"]: e for e in r["scales"]}
        cells = []
        for sc in scales:
            e = by.get(sc)
            if not e or not e["spawned"]:
                cells.append("<td>-</td>")
                continue
            self_pct, skip_pct = 100.0 * e["self_hits"] / e["spawned"], 100.0 * e["skipped_walls"] / e["spawned"]
            bad = ' class="bad"' if e["self_hits"] or e["skipped_walls"] else ""
            cells.append(f"<td{bad}>{self_pct:.3g} / {skip_pct:.3g}</td>")
        h.append(f'<tr><td class="l">{esc(r["kind"])}</td><td class="l">{esc(r["precision"])}</td>'
                 f'<td class="l">{esc(r["strategy"])}</td>' + "".join(cells) +
                 f"<td>{sum(e['spawned'] for e in r['scales'])}</td></tr>")
    h.append("</table>")
    return "".join(h)


def line_panel(ax, rows, methods, field, sweeps, numeric):
    xs_of = {sw: (float(sw) if numeric else i) for i, sw in enumerate(sweeps)}
    for method in dict.fromkeys(r["method"] for r in rows):
        rs = [r for r in rows if r["method"] == method and r[field] is not None]
        if not rs:
            continue
        rs.sort(key=lambda r: xs_of[r["sweep"]])
        doc = methods.is_document(method)
        ax.plot([xs_of[r["sweep"]] for r in rs], [r[field] for r in rs], marker="o", ms=3,
                ls="--" if doc else ":" if peer_subjects.is_peer(methods, method) else "-",
                color=methods.colour.get(method, "k"), label=peer_subjects.label(methods, method))
    if numeric:
        if min(xs_of.values()) > 0:
            ax.set_xscale("log")
        else:
            ax.set_xscale("symlog", linthresh=1)
    else:
        ax.set_xticks(list(xs_of.values()), sweeps, rotation=30, fontsize=7)
    ax.set_yscale("symlog", linthresh=1e-3 if field != "leaks" else 1)
    ax.set_ylim(bottom=0)


def chart_stability(stab, methods):
    charts = []
    for family, d in stab.items():
        rows = d["rows"]
        sweeps = list(dict.fromkeys(r["sweep"] for r in rows))
        if len(sweeps) < 2:
            continue
        precisions = list(dict.fromkeys(r["precision"] for r in rows))
        secondary = any(r["spawned"] for r in rows)
        grouped = any(r["groups"] for r in rows)
        if secondary and family == "refracted":
            # One row of panels per strategy: self-hits and skipped walls, float and double.
            strategies = list(dict.fromkeys(s.split("@")[0] for s in sweeps))
            panels = [(p, f, what) for p in precisions
                      for f, what in (("self_hit_pct", "self-hit %"), ("skip_pct", "skipped far wall %"))]
            fig, axes = plt.subplots(len(strategies), len(panels), figsize=(4.2 * len(panels), 2.4 * len(strategies)),
                                     squeeze=False, sharey=True)
            for i, st in enumerate(strategies):
                for j, (p, field, what) in enumerate(panels):
                    rs = [dict(r, sweep=r["sweep"].split("@")[1]) for r in rows
                          if r["precision"] == p and r["sweep"].split("@")[0] == st]
                    sw = list(dict.fromkeys(r["sweep"] for r in rs))
                    line_panel(axes[i][j], rs, methods, field, sw, True)
                    axes[i][j].set_title(f"{st}, {p}: {what}")
                    axes[i][j].set_xlabel("scale of the solid (log)")
            peer_subjects.legend(axes[0])
            caption = ("refracted: rays spawned into a closed mesh or a sphere from each method's own entry hit under "
                       "each self-intersection strategy; a self-hit meets the entry surface again, a skipped wall "
                       "misses the far wall (the strategy's window or offset passed it). Lower is better; 0 is the "
                       "goal. The table below sums the methods.")
            charts.append((family, svg_of(fig), caption))
            continue
        if secondary:
            # strategy@scale: one row of panels per self-intersection strategy.
            strategies = list(dict.fromkeys(s.split("@")[0] for s in sweeps))
            fig, axes = plt.subplots(len(strategies), len(precisions), figsize=(5.2 * len(precisions), 2.4 * len(strategies)),
                                     squeeze=False, sharey=True)
            for i, st in enumerate(strategies):
                for j, p in enumerate(precisions):
                    rs = [dict(r, sweep=r["sweep"].split("@")[1]) for r in rows
                          if r["precision"] == p and r["sweep"].split("@")[0] == st]
                    sw = list(dict.fromkeys(r["sweep"] for r in rs))
                    line_panel(axes[i][j], rs, methods, "self_hit_pct", sw, True)
                    axes[i][j].set_title(f"{st}, {p}: self-hit % of secondary rays")
                    axes[i][j].set_xlabel("scale of the triangle (log)")
            peer_subjects.legend(axes[0])
            caption = ("secondary: rays spawned from each method's own hit under each self-intersection strategy; "
                       "a self-hit re-hits the triangle it left (shadow acne). Lower is better; 0 is the goal.")
            charts.append((family, svg_of(fig), caption))
            continue
        numeric = all(sweep_number(s) is not None for s in sweeps)
        fields = [("wrong_pct", "wrong %")]
        if grouped:
            fields.append(("leaks", "leaks (rays through a closed group)"))
        fig, axes = plt.subplots(len(fields), len(precisions), figsize=(5.2 * len(precisions), 2.6 * len(fields)),
                                 squeeze=False)
        for i, (field, label) in enumerate(fields):
            for j, p in enumerate(precisions):
                rs = [r for r in rows if r["precision"] == p]
                line_panel(axes[i][j], rs, methods, field, sweeps, numeric)
                axes[i][j].set_title(f"{family}, {p}: {label}")
                axes[i][j].set_xlabel(d["param"] + (" (log)" if numeric else ""))
        # Same y range for float and double so they compare at a glance.
        for i in range(len(fields)):
            top = max(ax.get_ylim()[1] for ax in axes[i])
            for ax in axes[i]:
                ax.set_ylim(0, top)
        peer_subjects.legend(axes[0])
        how = f"as the {d['param']} grows" if numeric else f"for each {d['param']}"
        caption = (f"{family}: how each method fares {how}; float left, double right, "
                   "dashed lines are the seed documents' methods, dotted ones peers (other projects' own code). "
                   "Flat at 0 is right; a rising line is where "
                   "that method breaks.")
        charts.append((family, svg_of(fig), caption))
    return charts


# ---------------------------------------------------------------- section 3 --


def crack_maps(cm, cm_dir):
    out = []
    for m in cm["maps"]:
        out.append({k: m[k] for k in ("mesh", "method", "precision", "offset", "pixels", "surface_pixels",
                                       "leaks", "false_hits")}
                   | {"image": os.path.join(cm_dir, m["image"])})
    return out


def chart_crack_leaks(maps, methods):
    meshes = list(dict.fromkeys(m["mesh"] for m in maps))
    fig, axes = plt.subplots(1, len(meshes), figsize=(5.2 * len(meshes), 3.2), squeeze=False)
    for ax, mesh in zip(axes[0], meshes):
        ms = [m for m in maps if m["mesh"] == mesh]
        for method in dict.fromkeys(m["method"] for m in ms):
            rs = sorted((m for m in ms if m["method"] == method), key=lambda m: m["offset"])
            ax.plot([max(m["offset"], 1e-1) for m in rs], [m["leaks"] for m in rs], marker="o", ms=3,
                    ls="--" if methods.is_document(method) else "-", color=methods.colour.get(method, "k"),
                    label=methods.label(method))
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=1)
        ax.set_ylim(bottom=0)
        ax.set_xlabel("offset of the mesh from the origin (log)")
        ax.set_ylabel("leaking pixels")
        ax.set_title(f"{mesh}: leaking pixels in float")
    axes[0][-1].legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1))
    return svg_of(fig)


# ---------------------------------------------------------------- section 4 --


def optimisations(bench):
    rows = bench_rows(bench)
    scene = []
    for name, b in rows.items():
        parts, keys = parse_bench_name(name)
        if parts[:1] != ["scene"] or len(parts) < 5 or not b.get("Mrays_per_s"):
            continue
        scene.append({"name": name, "mesh": parts[1], "accel": parts[2], "cull": parts[3] == "cull",
                      "rays": parts[4], "threads": keys.get("threads", "1"),
                      "triangles": b.get("triangles"), "Mrays_per_s": float(b["Mrays_per_s"]),
                      "Mrays_spread": b["_spread"].get("Mrays_per_s"), "rays_traced": b.get("rays"),
                      "flagged": b["_flagged"],
                      "build_s": b.get("build_s"), "bytes_per_triangle": b.get("bytes_per_triangle")})
    index = {(r["mesh"], r["accel"], r["cull"], r["rays"], r["threads"]): r for r in scene}
    one = min((r["threads"] for r in scene), key=lambda t: int(t) if t.isdigit() else 1e9, default="1")
    speedups = []

    def speedup(r, base, what):
        # The spread of a ratio of medians: the quartiles crossed (the
        # optimised row's lower quartile over the base's upper, and back).
        sa, sb = r["Mrays_spread"], base["Mrays_spread"]
        lo_hi = (sa["q1"] / sb["q3"], sa["q3"] / sb["q1"]) if sa and sb and sb["q1"] > 0 else None
        speedups.append({"mesh": r["mesh"], "triangles": r["triangles"], "rays": r["rays"], "what": what,
                         "speedup": r["Mrays_per_s"] / base["Mrays_per_s"], "spread": lo_hi,
                         "rays_traced": r["rays_traced"], "flagged": "; ".join(x for x in (r["flagged"], base["flagged"]) if x)})

    for r in scene:
        if r["threads"] != one:
            continue
        if r["accel"] in ("sphere", "bvh") and not r["cull"]:
            base = index.get((r["mesh"], "none", False, r["rays"], r["threads"]))
            if base and base["Mrays_per_s"] > 0:
                speedup(r, base, f"{r['accel']} over none")
        # Shadow rays are any-hit tests that ignore facing: culling changes
        # no work there, so their ratio is noise and is not charted.
        if r["cull"] and r["rays"] != "shadow":
            base = index.get((r["mesh"], r["accel"], False, r["rays"], r["threads"]))
            if base and base["Mrays_per_s"] > 0:
                speedup(r, base, f"culling ({r['accel']})")
    scaling = []
    for accel in dict.fromkeys(r["accel"] for r in scene):
        rs = sorted((r for r in scene if r["accel"] == accel and not r["cull"] and r["rays"] == "primary"
                     and r["threads"] == one and r["triangles"]), key=lambda r: r["triangles"])
        if not rs:
            continue
        n = np.array([float(r["triangles"]) for r in rs])
        ns = np.array([1e3 / r["Mrays_per_s"] for r in rs])
        slope = float(np.polyfit(np.log10(n), np.log10(ns), 1)[0]) if len(rs) >= 2 else None
        # ns per ray is 1000 / Mrays per s: the rate's upper quartile is the time's lower.
        q = [(1e3 / r["Mrays_spread"]["q3"], 1e3 / r["Mrays_spread"]["q1"]) if r["Mrays_spread"] else None for r in rs]
        scaling.append({"accel": accel, "triangles": n.tolist(), "ns_per_ray": ns.tolist(), "slope": slope,
                        "ns_quartiles": q, "meshes": [r["mesh"] for r in rs]})
    return {"threads": one, "scene_rows": scene, "speedups": speedups, "scaling": scaling}


def ratio_bars(ax, labels, vals, spreads, colour, vertical=True, width=0.8, offset=0.0, label=None):
    """Bars from 1x to each ratio with their spread as error bars and the
    ratio written past the bar's end; returns the values the axis must hold
    and the text labels."""
    pos = np.arange(len(labels)) + offset
    base = [min(v, 1.0) for v in vals]
    size = [abs(v - 1.0) for v in vals]
    if vertical:
        ax.bar(pos, size, width, bottom=base, color=colour, label=label)
    else:
        ax.barh(pos, size, width, left=base, color=colour, label=label)
    held, texts = list(vals), []
    for p, v, sp in zip(pos, vals, spreads):
        if not (v == v):
            continue
        end = v
        if sp:
            err = [[max(v - sp[0], 0)], [max(sp[1] - v, 0)]]
            if vertical:
                ax.errorbar([p], [v], yerr=err, fmt="none", ecolor="k", lw=0.9, capsize=2)
            else:
                ax.errorbar([v], [p], xerr=err, fmt="none", ecolor="k", lw=0.9, capsize=2)
            held += list(sp)
            end = sp[1] if v >= 1 else sp[0]
        up = v >= 1
        if vertical:
            texts.append(ax.annotate(perf.ratio_text(v), (p, end), textcoords="offset points",
                                     xytext=(0, 2 if up else -2), ha="center", va="bottom" if up else "top",
                                     fontsize=6.5))
        else:
            texts.append(ax.annotate(perf.ratio_text(v), (end, p), textcoords="offset points",
                                     xytext=(3 if up else -3, 0), ha="left" if up else "right", va="center",
                                     fontsize=6.5))
    return held, texts


def chart_optimisations(opt):
    charts = []
    sp = opt["speedups"]
    if sp:
        raykinds = list(dict.fromkeys(s["rays"] for s in sp))
        groups = [("accelerator over none", [w for w in dict.fromkeys(s["what"] for s in sp) if "over none" in w]),
                  ("backface culling", [w for w in dict.fromkeys(s["what"] for s in sp) if w.startswith("culling")])]
        groups = [g for g in groups if g[1]]
        panels = [(g, rk) for g in groups for rk in raykinds
                  if any(s["rays"] == rk and s["what"] in g[1] for s in sp)]
        fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 3.6), squeeze=False)
        cmap = plt.get_cmap("tab10")
        for ax, ((gname, whats), rk) in zip(axes[0], panels):
            meshes = sorted(dict.fromkeys(s["mesh"] for s in sp if s["rays"] == rk and s["what"] in whats),
                            key=lambda m: next(s["triangles"] or 0 for s in sp if s["mesh"] == m))
            w = 0.8 / max(1, len(whats))
            held, texts = [], []
            for k, what in enumerate(whats):
                found = [next((s for s in sp if s["mesh"] == m and s["what"] == what and s["rays"] == rk), None)
                         for m in meshes]
                vals = [s["speedup"] if s else np.nan for s in found]
                spreads = [s["spread"] if s else None for s in found]
                h, t = ratio_bars(ax, meshes, vals, spreads, cmap(k % 10), width=w, offset=k * w - 0.4 + w / 2,
                                  label=what)
                held += h
                texts += t
            lim = perf.ratio_axis(ax, held, axis="y")
            ax.set_xticks(np.arange(len(meshes)), meshes, rotation=15, fontsize=7)
            ax.set_xlim(-0.6, len(meshes) - 0.4)
            ax.set_ylabel("speed-up (x, log; 1x: no change)")
            rays = sorted({s["rays_traced"] for s in sp if s["rays"] == rk and s["what"] in whats and s["rays_traced"]})
            ax.set_title(f"{gname}: {rk} rays, {opt['threads']} thread(s)\n"
                         f"{'/'.join(f'{int(r):,}' for r in rays) if rays else '?'} rays a pass", fontsize=8.5)
            ax.legend(fontsize=7, loc="lower left")
            CHART_FACTS.append(perf.axis_facts(ax, f"optimisations/{gname}/{rk}", ratio={"axis": "y", "limits": lim,
                                                                                          "bars_from": 1.0},
                                               labels=perf.count_overlaps(fig, texts)))
        perf.stamp(fig, STAMP[0])
        charts.append((svg_of(fig), "Each bar is rays per second with the optimisation divided by without it, "
                       "per rung of the mesh ladder (smallest left), drawn from 1x: up, it pays; down, it costs. "
                       "Error bars: the optimised row's quartiles over the base row's (low: its lower quartile over "
                       "the base's upper). Culling is charted for primary rays only: shadow rays are any-hit tests "
                       "that ignore facing, so culling does the same work there."))
    if opt["scaling"]:
        fig, ax = plt.subplots(figsize=(6.5, 4))
        for s in opt["scaling"]:
            lab = s["accel"] + (f" (slope {s['slope']:.2f})" if s["slope"] is not None else "")
            q = s.get("ns_quartiles") or []
            err = None
            if q and all(q):
                err = [[max(y - lo, 0) for y, (lo, _) in zip(s["ns_per_ray"], q)],
                       [max(hi - y, 0) for y, (_, hi) in zip(s["ns_per_ray"], q)]]
            ax.errorbar(s["triangles"], s["ns_per_ray"], yerr=err, marker="o", capsize=2, label=lab)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("triangles in the mesh (log)")
        ax.set_ylabel("ns per primary ray (log; bars: quartiles)")
        ax.set_title("Cost per ray against mesh size")
        ax.legend(fontsize=7)
        perf.stamp(fig, STAMP[0])
        CHART_FACTS.append(perf.axis_facts(ax, "scaling"))
        charts.append((svg_of(fig), "Slope 1 means the cost grows with the triangle count (every triangle "
                       "tested); near 0 means it barely grows (a BVH should be logarithmic)."))
    return charts


# ---------------------------------------------------------------- section 5 --


def peers(bench):
    out = []
    for name, b in bench_rows(bench).items():
        parts, _ = parse_bench_name(name)
        if parts[:1] == ["peer"] and len(parts) >= 2 and "ratio" in b:
            sp = b["_spread"].get("ratio")
            out.append({"name": name, "peer": parts[1], "ratio": float(b["ratio"]),
                        "spread": (sp["q1"], sp["q3"]) if sp else None,
                        "range": (sp["min"], sp["max"]) if sp else None, "rays": b.get("rays"),
                        "flagged": b["_flagged"]})
    return out


def chart_peers(ps):
    if not ps:
        return None
    fig, ax = plt.subplots(figsize=(8, 0.3 * len(ps) + 1.6))
    cmap = plt.get_cmap("tab10")
    names = list(dict.fromkeys(p["peer"] for p in ps))
    ys = np.arange(len(ps))
    held, texts = [], []
    for i, p in enumerate(ps):
        h, t = ratio_bars(ax, [p["name"]], [p["ratio"]], [p["spread"]], cmap(names.index(p["peer"]) % 10),
                          vertical=False, offset=i)
        held += h
        texts += t
    ax.set_yticks(list(ys), [re.sub(r"^peer/", "", p["name"]) + (" (!)" if p["flagged"] else "") for p in ps],
                  fontsize=6.5)
    lim = perf.ratio_axis(ax, held, axis="x")
    ax.set_ylim(len(ps) - 0.5, -0.5)
    ax.set_xlabel("rayaudit's rate / the peer's (log, bars from 1x): right, rayaudit is faster; left, the peer\n"
                  "error bars: quartiles of the per-repetition ratios (each measured back to back); (!) flagged")
    ax.set_title("rayaudit against its peers, same rays, same run")
    perf.stamp(fig, STAMP[0])
    CHART_FACTS.append(perf.axis_facts(ax, "peers", ratio={"axis": "x", "limits": lim, "bars_from": 1.0},
                                       labels=perf.count_overlaps(fig, texts)))
    return svg_of(fig)


# ---------------------------------------------------------------- section 6 --


def images(compare_dirs):
    out = []
    for d in compare_dirs:
        for f in sorted(glob.glob(os.path.join(d, "*.json"))):
            j = load_json(f)
            if "identical" not in j or "differences" not in j:
                continue  # not a compare output (e.g. a tolerance file)
            stem = os.path.splitext(os.path.basename(f))[0]
            thumbs = {}
            for kind, suffix in (("ours", "-ours.png"), ("pov", "-pov.png"), ("diff", "-diff.png")):
                p = os.path.join(d, stem + suffix)
                if os.path.exists(p):
                    thumbs[kind] = p
            causes = {(e["x"], e["y"]): e["cause"] for e in j.get("explanations", [])}
            out.append({
                "name": stem,
                "scene": j.get("scene", stem),
                "width": j["width"], "height": j["height"],
                "identical": j["identical"],
                "differing": j["differing"],
                "within_tolerance": j.get("within_tolerance"),
                "verdict": j.get("verdict", []),
                "psnr": j.get("psnr"),
                "differences": [{"x": e["x"], "y": e["y"], "levels": e["levels"],
                                 "cause": causes.get((e["x"], e["y"]))} for e in j["differences"]],
                "files": thumbs,
            })
    return out


# ---------------------------------------------------------------- section 7 --


def run(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def machine(ctx, audit, bench, stages):
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    versions = {}
    for label, pkg in (("Embree", "libembree-dev"), ("POV-Ray", "povray"), ("CGAL", "libcgal-dev"),
                       ("OpenImageIO", "libopenimageio-dev"), ("Google Benchmark", "libbenchmark-dev"),
                       ("matplotlib", "python3-matplotlib"), ("Chromium", "chromium")):
        versions[label] = run(["dpkg-query", "-W", "-f=${Version}", pkg]) or "not installed"
    src = ctx.get("source_dir", "")
    commit = run(["git", "-C", src, "rev-parse", "--short=12", "HEAD"]) if src else ""
    dirty = run(["git", "-C", src, "status", "--porcelain", "--untracked-files=no"]) if src else ""
    ctxb = bench["runs"][0]["context"] if bench else {}
    here = perf.local_machine()
    bm = next((r["machine"] for r in (bench or {}).get("runs", []) if r.get("machine")), None) or here
    steal = [r["steal_pct"] for r in (bench or {}).get("runs", []) if r.get("steal_pct") is not None]
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "bench_machine": bm,
        "machine_line": ("benchmarks ran on: " if bench else "") +
                        perf.machine_line(bm, max(steal) if steal else None) +
                        ("" if not bench or bm.get("cpu_model") == here.get("cpu_model") else
                         "; this page was drawn on: " + perf.machine_line(here)),
        "bench_context": {k: ctxb[k] for k in ("host_name", "num_cpus", "mhz_per_cpu", "library_build_type", "date")
                          if k in ctxb},
        "compiler": ctx["build"]["compiler"],
        "flags": ctx["build"]["flags"],
        "build_type": ctx["build"]["build_type"],
        "rayaudit": ctx["build"]["version"],
        "commit": (commit + (" (with uncommitted changes)" if dirty else "")) or "unknown",
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "versions": versions,
        "seed": (audit or {}).get("seed"),
        "rays_per_family": (audit or {}).get("rays_per_family"),
        "audit_inputs": (audit or {}).get("_inputs", []),
        "stages": stages,
    }


# --------------------------------------------------------------------- page --

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0 auto;max-width:1280px;padding:0 18px 40px;color:#222}
h1{margin:18px 0 4px;font-size:24px} h2{margin-top:34px;border-bottom:2px solid #ddd;padding-bottom:3px}
h3{margin:18px 0 4px;font-size:15px}
.cap{color:#444;font-size:13px;margin:2px 0 14px;font-style:italic}
.chart svg{max-width:100%;height:auto}
table{border-collapse:collapse;font-size:12px;margin:6px 0 14px} td,th{border:1px solid #ddd;padding:3px 6px;text-align:right}
th{background:#f4f4f4} td.l,th.l{text-align:left}
.ok{color:#176d2c;font-weight:600} .bad{color:#b00020;font-weight:600} .warn{color:#9a6700;font-weight:600}
.grid td{text-align:center;vertical-align:top} .grid img{image-rendering:pixelated;width:112px;height:112px;display:block;margin:auto}
.thumbs img{max-width:160px;image-rendering:pixelated;border:1px solid #ccc}
.keyfacts{display:flex;gap:12px;flex-wrap:wrap;margin:10px 0} .keyfacts div{background:#f6f8fa;border:1px solid #ddd;border-radius:6px;padding:8px 12px;font-size:13px}
.notice{background:#fff8e1;border:1px solid #f0c36d;padding:8px 12px;border-radius:6px}
dl.hdr{display:grid;grid-template-columns:max-content 1fr;gap:2px 14px;font-size:12.5px} dl.hdr dt{font-weight:600}
"""

# Runs in the browser: every image decoded and every chart drawn, or a console
# error saying which is not (the Chromium ctest reads both).
SELF_CHECK = """
window.addEventListener('load', function () {
  var bad = [], imgs = document.images, svgs = document.querySelectorAll('.chart svg');
  for (var i = 0; i < imgs.length; i++)
    if (!imgs[i].complete || imgs[i].naturalWidth === 0) bad.push('image ' + (imgs[i].alt || i));
  for (var k = 0; k < svgs.length; k++) {
    var b = svgs[k].getBBox();
    if (!(b.width > 0 && b.height > 0) || svgs[k].querySelectorAll('path,use,text').length === 0) bad.push('chart ' + k);
  }
  var r = document.getElementById('selfcheck');
  r.setAttribute('data-images', imgs.length);
  r.setAttribute('data-charts', svgs.length);
  r.setAttribute('data-result', bad.length ? 'FAIL' : 'ok');
  r.textContent = bad.length ? 'self-check failed: ' + bad.join(', ')
                             : 'self-check: ' + imgs.length + ' images and ' + svgs.length + ' charts drawn';
  if (bad.length) console.error('report self-check failed: ' + bad.join(', '));
});
"""


def perf_facts(rep):
    """The headlines about speed and rightness, each with its rule, so that
    they agree with the tables below them."""
    facts = []
    sa = [e for e in rep["speed_accuracy"] if e["kind"] == "triangle"]
    timed = [e for e in sa if e["ns_per_test"] is not None]
    if timed:
        f = min(timed, key=lambda e: e["ns_per_test"])
        sp = f.get("ns_spread")
        spread = f", quartiles {fnum(sp['q1'])}-{fnum(sp['q3'])}" if sp else ""
        # Others whose quartiles reach the winner's: not told apart by this run.
        ties = [e for e in timed if e is not f and e.get("ns_spread") and sp and e["ns_spread"]["q1"] <= sp["q3"]]
        tie = (f"; not told apart from {', '.join(esc(e['subject']) for e in ties)} (quartiles overlap)"
               if ties else "")
        facts.append(f"Fastest triangle test (lowest median ns per test, kernel bench at 50% hits, no culling; "
                     f"{esc(STAMP[0])}): <b>{esc(f['subject'])}</b> at {fnum(f['ns_per_test'])} ns{spread}"
                     f" ({fnum(f['wrong_pct'])}% wrong){tie}" + (" <span class=\"warn\">flagged</span>"
                                                                 if f.get("ns_flagged") else ""))
    if len(sa) == 1:
        # One subject is not "most right" of anything.
        e = sa[0]
        facts.append(f"One triangle subject: <b>{esc(e['subject'])}</b> "
                     f"({fnum(e['wrong_pct'])}% wrong, {e['leaks']:,} leaks)")
    elif sa:
        right = min(sa, key=lambda e: (e["leaks"] > 0, e["wrong_pct"], e["ns_per_test"] or 0))
        fewer = [e for e in sa if e["wrong_pct"] < right["wrong_pct"]]
        rule = ("rule: leak-free methods first, then the fewest wrong answers, then the fastest"
                if any(e["leaks"] == 0 for e in sa) else "rule: the fewest wrong answers (every method leaks)")
        below = ("; ranked below it for leaking: " + ", ".join(
            f"{esc(e['subject'])} ({fnum(e['wrong_pct'])}% wrong, {e['leaks']:,} leaks)" for e in fewer)) if fewer else ""
        facts.append(f"Most right ({rule}): <b>{esc(right['subject'])}</b> ({fnum(right['wrong_pct'])}% wrong, "
                     f"{right['leaks']:,} leaks){below}")
    return facts


def audit_words(m):
    """The run's real seed and rays, and what each --audit file holds."""
    inputs = m.get("audit_inputs") or []
    generated = m["rays_per_family"] not in (None, 0)
    text = (f"seed {m['seed']}, {m['rays_per_family']} ray/primitive tests per family per method x precision"
            if generated else "graded answers on cases given by hand (not generated: no seed)")
    if len(inputs) > 1 or any(i.get("graded") for i in inputs):
        parts = []
        for i in inputs:
            what = ", ".join(i["subjects"])
            if i.get("graded"):
                g = i["graded"]
                what += f" (answers {g.get('answers', '?')} on the cases {g.get('cases', '?')})"
            parts.append(f"{os.path.basename(i['file'])}: {what}")
        text += "; " + "; ".join(parts)
    return text


def merge_audits(paths):
    """Several audits of the same seed and rays (rayaudit report checked) as one."""
    merged = None
    for p in paths:
        a = load_json(p)
        entry = {"file": p, "subjects": [s["name"] for s in a["subjects"]], "graded": a.get("graded")}
        if merged is None:
            merged = dict(a, subjects=list(a["subjects"]), cells=list(a["cells"]), _inputs=[entry])
            continue
        merged["subjects"] += a["subjects"]
        merged["cells"] += a["cells"]
        merged["_inputs"].append(entry)
    return merged


def read_timings(path):
    """subject,ns_per_test (validation/baseline/timing.h) as {subject: ns}."""
    current_input[0] = path
    out = {}
    with open(path, encoding="utf-8-sig") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or line == "subject,ns_per_test":
                continue
            subject, ns = line.rsplit(",", 1)
            out[subject] = float(ns)
    return out


def chart_html(svg, caption):
    return f'<div class="chart">{svg}</div><p class="cap">{esc(caption)}</p>'


def page(rep, charts, methods, uris):
    m = rep["machine"]
    h = ['<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">',
         '<meta name="viewport" content="width=device-width, initial-scale=1">',
         "<title>rayaudit report</title>", f"<style>{CSS}</style>", f"<script>{SELF_CHECK}</script>",
         "</head><body>", "<h1>rayaudit report: speed against accuracy</h1>"]
    # ---- key facts: what a newcomer wants first.
    sa = [e for e in rep["speed_accuracy"] if e["kind"] == "triangle"]
    facts = []
    facts += perf_facts(rep)
    if sa:
        leakfree = [e["subject"] for e in sa if e["leaks"] == 0]
        facts.append("Leak-free (no ray through a closed group): " +
                     (", ".join(f"<b>{esc(s)}</b>" for s in leakfree) if leakfree else "<b>none</b>"))
    if rep["images"]:
        bad = [i["name"] for i in rep["images"] if i["within_tolerance"] is False]
        facts.append("POV-Ray comparisons: " + (f'<span class="bad">{len(bad)} beyond tolerance</span>' if bad
                                                 else f'<span class="ok">all {len(rep["images"])} within tolerance</span>'))
    h.append('<div class="keyfacts">' + "".join(f"<div>{f}</div>" for f in facts) + "</div>")
    h.append('<p id="selfcheck" data-result="pending">self-check: pending</p>')

    # ---- 7 header (first on the page: what the figures rest on).
    h.append("<h2>The run</h2>")
    h.append('<p class="cap">What these figures were measured on; every ratio below is from this one run.</p><dl class="hdr">')
    rows = [("Machine", m["machine_line"]), ("Compiler", m["compiler"]),
            ("Flags", f"{m['flags']} ({m['build_type']})"), ("rayaudit", f"{m['rayaudit']}, commit {m['commit']}"),
            ("Date", m["date"]),
            ("Libraries", ", ".join(f"{k} {v}" for k, v in m["versions"].items()))]
    if rep["have_audit"]:
        rows.append(("Audit", audit_words(m)))
    if rep["have_bench"]:
        rows.append(("Benchmark runs", f"{len(rep['bench_runs'])} JSON(s): {STAMP[0]}"))
    if m["bench_context"]:
        names = {"host_name": "host", "num_cpus": "CPUs", "mhz_per_cpu": "MHz",
                 "library_build_type": "Google Benchmark library built as", "date": "run at"}
        rows.append(("Benchmark", ", ".join(f"{names.get(k, k)} {v}" for k, v in m["bench_context"].items())))
    if m["stages"]:
        rows.append(("Stages", ", ".join(f"{esc(s['stage'])} {s['seconds']:.0f} s" for s in m["stages"])))
    for k, v in rows:
        h.append(f"<dt>{esc(k)}</dt><dd>{esc(v)}</dd>")
    h.append("</dl>")

    # ---- 1
    if rep["have_bench"]:
        h.append("<h3>Steadiness of the benchmark figures</h3>")
        h.append('<p class="cap">Each figure below is the median of its repetitions (interleaved: every row once per '
                 "repetition) and, over several runs, the median of the runs' medians; error bars show the quartiles, "
                 "ranges the minimum and maximum over every repetition used. A calibration workload timed beside every "
                 f"row finds slow phases: a run {100 * (perf.SLOW_FACTOR - 1):.0f}% slower than the fastest is left "
                 f"out; a row whose runs' medians span more than {100 * perf.DISAGREE:.0f}% (and more than its "
                 "quartiles) is flagged.</p>")
        h.append(perf.spread_table_html(rep["bench"], esc, fnum))
    h.append("<h2>1. Speed against accuracy</h2>")
    if not rep["have_audit"]:
        h.append('<p class="notice">No audit given: a performance-only report (run <code>rayaudit audit --json '
                 'A.json</code> and pass <code>--audit A.json</code> for the correctness sections).</p>')
    if not rep["have_bench"]:
        h.append('<p class="notice">No benchmark given: speeds are missing (run <code>rayaudit bench --quick '
                 '--json B.json</code> and pass <code>--bench B.json</code>).</p>')
    for svg, cap in charts["speed_accuracy"]:
        h.append(chart_html(svg, cap))
    if charts.get("kernel_hit_rate"):
        h.append("<h3>Cost of a test against hit rate</h3>")
        h.append(chart_html(charts["kernel_hit_rate"], "Löfstedt & Akenine-Möller's sweep: every kernel row without "
                            "culling or back faces, at each hit rate of the batch (a test that misses early costs "
                            "less). Error bars: quartiles; shaded: min-max over repetitions and runs. y from 0."))
    h.append('<table><tr><th class="l">method/precision</th><th>ns per test</th><th>wrong %</th><th>leaks</th>'
             '<th>leaks per million</th><th>tests</th><th class="l">breaks worst at (family@sweep)</th>'
             '<th class="l">source</th></tr>')
    for e in rep["speed_accuracy"]:
        src = e.get("speed_source") or methods.by_name.get(e["method"], {}).get("source", "")
        w = e.get("worst")
        worst = f"{w['family']}@{w['sweep']} ({100 * w['badness']:.3g}% bad)" if w else "nowhere"
        h.append(f'<tr><td class="l">{esc(peer_subjects.label(methods, e["method"]))}/{esc(e["precision"])}</td>'
                 f"<td>{fnum(e['ns_per_test'])}</td><td>{fnum(e['wrong_pct'])}</td><td>{e['leaks']}</td>"
                 f"<td>{fnum(e['leaks_per_million'])}</td><td>{e['tests']}</td>"
                 f"<td class=\"l\">{esc(worst)}</td><td class=\"l\">{esc(src)}</td></tr>")
    h.append("</table>")

    # ---- 2
    h.append("<h2>2. Stability: where each method breaks</h2>")
    h.append('<p class="cap">Every audit family with a sweep. y axes are linear near 0 and logarithmic above, '
             "so a single wrong answer shows.</p>")
    if not rep["have_audit"]:
        h.append('<p class="notice">No audit given: no stability sweeps.</p>')
    for family, svg, cap in charts["stability"]:
        h.append(f"<h3>{esc(family)}</h3>" + chart_html(svg, cap))
        if family == "refracted":
            h.append(refracted_table_html(rep["refracted"]))

    # ---- 3
    h.append("<h2>3. Crack maps</h2>")
    if not rep["crack_maps"]:
        h.append('<p class="notice">No crack maps given (<code>rayaudit crack-maps -o DIR</code>, then '
                 "<code>--crack-maps DIR</code>).</p>")
    else:
        h.append(chart_html(charts["crack_leaks"], "Leaking pixels (rays through the closed surface) of each method "
                            "in float as the mesh moves away from the origin, where every ray starts: 0 is right."))
        cm = rep["crack_maps"]
        for mesh in dict.fromkeys(c["mesh"] for c in cm):
            info = next((x for x in rep["crack_meshes"] if x["name"] == mesh), {})
            h.append(f"<h3>{esc(mesh)}: {esc(info.get('source', ''))}, {info.get('triangles', '?')} triangles</h3>")
            offsets = sorted(dict.fromkeys(c["offset"] for c in cm if c["mesh"] == mesh))
            h.append('<table class="grid"><tr><th class="l">method (float)</th>' +
                     "".join(f"<th>offset {offset_label(o)}</th>" for o in offsets) + "</tr>")
            for method in dict.fromkeys(c["method"] for c in cm if c["mesh"] == mesh):
                h.append(f'<tr><td class="l">{esc(methods.label(method))}</td>')
                for o in offsets:
                    c = next((c for c in cm if c["mesh"] == mesh and c["method"] == method and c["offset"] == o), None)
                    if not c:
                        h.append("<td>-</td>")
                        continue
                    cls = "ok" if c["leaks"] == 0 else "bad"
                    extra = f", {c['false_hits']} false" if c["false_hits"] else ""
                    h.append(f'<td><img alt="{esc(mesh)} {esc(method)} {fnum(o)}" src="{uris[c["image"]]}">'
                             f'<span class="{cls}">{c["leaks"]} leaks</span>{esc(extra)}</td>')
                h.append("</tr>")
            h.append("</table>")
        h.append(f'<p class="cap">{esc(rep["crack_legend"])}. Each map: the mesh centred at (o, o, o), '
                 "seen from the origin once o is beyond 6.5 (every ray then starts at the origin, as in a large "
                 "world), one ray per pixel, everything in float; the oracle judges each float ray exactly.</p>")

    # ---- 4
    h.append("<h2>4. Optimisations</h2>")
    if not rep["have_bench"]:
        h.append('<p class="notice">No benchmark given: the optimisations are not measured here.</p>')
    elif not charts["optimisations"]:
        h.append('<p class="notice">The benchmark has no scene/ rows.</p>')
    for svg, cap in charts["optimisations"]:
        h.append(chart_html(svg, cap))

    # ---- 5
    h.append("<h2>5. Peers</h2>")
    if not rep["have_bench"]:
        h.append('<p class="notice">No benchmark given: no peer ratios.</p>')
    elif charts["peers"]:
        h.append(chart_html(charts["peers"], "Each bar: rayaudit's rate divided by the peer's on the same input in "
                            "the same run (medians). Right of the line rayaudit is faster."))
    else:
        h.append('<p class="notice">The benchmark has no peer/ rows.</p>')

    # ---- 6
    h.append(tracers_report.html(rep["tracers"], charts["tracers"], esc, chart_html))
    h.append("<h2>6. Images: rayaudit against POV-Ray 3.7</h2>")
    if not rep["images"]:
        h.append('<p class="notice">No comparisons given (<code>--compare DIR</code>).</p>')
    else:
        h.append('<p class="cap">Each scene as we render it, as POV-Ray 3.7 renders it, and their difference '
                 "(false colour; black is equal; each differing pixel ringed in yellow). Every differing pixel is "
                 "listed with the cause --explain found.</p>")
        h.append('<table class="thumbs"><tr><th class="l">scene</th><th>ours</th><th>POV-Ray</th><th>difference</th>'
                 '<th class="l">verdict</th></tr>')
        for im in rep["images"]:
            cells = []
            for kind in ("ours", "pov", "diff"):
                p = im["files"].get(kind)
                cells.append(f'<td><img alt="{esc(im["name"])} {kind}" src="{uris[p]}"></td>' if p else "<td>-</td>")
            status = ('<span class="ok">identical</span>' if im["identical"] else
                      (f'<span class="ok">{im["differing"]} pixel(s) differ, within tolerance</span>'
                       if im["within_tolerance"] else f'<span class="bad">{im["differing"]} pixel(s) differ</span>'))
            diffs = "".join(f"<li>({d['x']}, {d['y']}) {d['levels']} level(s): "
                            f"{esc(d['cause'] if d['cause'] else ('none of the known causes' if d['cause'] == '' else 'not explained (run with --explain)'))}</li>"
                            for d in im["differences"][:12])
            more = f"<li>... {len(im['differences']) - 12} more</li>" if len(im["differences"]) > 12 else ""
            h.append(f'<tr><td class="l">{esc(im["name"])}<br><small>{im["width"]}x{im["height"]}</small></td>'
                     + "".join(cells) + f'<td class="l">{status}<ul>{diffs}{more}</ul></td></tr>')
        h.append("</table>")
    h.append("<h3>Golden images</h3>")
    if rep["golden"] is None:
        h.append('<p class="notice">No golden check given (<code>--golden FILE</code>).</p>')
    else:
        h.append('<table><tr><th class="l">scene</th><th class="l">status</th><th class="l">detail</th></tr>')
        for g in rep["golden"]:
            cls = {"ok": "ok", "fail": "bad"}.get(g["status"], "warn")
            h.append(f'<tr><td class="l">{esc(g["name"])}</td><td class="l {cls}">{esc(g["status"])}</td>'
                     f'<td class="l">{esc(g["message"])}</td></tr>')
        h.append("</table>")
    h.append("</body></html>")
    return "\n".join(h)


def finite(v):
    """JSON has no NaN or infinity (Google Benchmark writes them): null instead."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, dict):
        return {k: finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [finite(x) for x in v]
    return v


def main():
    ctx = load_json(sys.argv[1])
    # The file names as bytes (hex): exact even when not UTF-8.
    for k, v in ctx.get("fs_paths", {}).items():
        ctx[k] = [os.fsdecode(bytes.fromhex(h)) for h in v] if isinstance(v, list) else os.fsdecode(bytes.fromhex(v))
    methods = Methods(ctx["methods"])
    audit = merge_audits(ctx.get("audits") or ([ctx["audit"]] if ctx.get("audit") else []))
    if audit:
        peer_subjects.register(methods, audit)
        for s in audit["subjects"]:
            if not peer_subjects.is_peer(methods, s["method"]):
                methods.add_user(s["method"])
    timings = read_timings(ctx["timings"]) if ctx.get("timings") else {}
    bench_paths = ctx.get("bench") or []
    if isinstance(bench_paths, str):
        bench_paths = [bench_paths]
    bench = None
    if bench_paths:
        loaded = [(p, load_json(p)) for p in bench_paths]
        current_input[0] = ", ".join(bench_paths)
        bench = perf.combine(loaded)
    cm, cm_dir = None, ctx.get("crack_maps")
    if cm_dir:
        cm = load_json(os.path.join(cm_dir, "crack_maps.json"))
    golden = None
    if ctx.get("golden"):
        golden = load_json(ctx["golden"])["scenes"]
    stages = []
    if ctx.get("stages"):
        current_input[0] = ctx["stages"]
        with open(ctx["stages"]) as f:
            for line in f:
                if line.strip():
                    name, secs = line.rstrip("\n").rsplit("\t", 1)
                    stages.append({"stage": name, "seconds": float(secs)})
    current_input[0] = ctx["audit"] or current_input[0]
    mach = machine(ctx, audit, bench, stages)
    if bench:
        STAMP[0] = f"{perf.mode_text(bench)}; {perf.short_machine(mach['bench_machine'])}"

    rep = {
        "have_bench": bench is not None,
        "have_audit": audit is not None,
        "speed_accuracy": speed_accuracy(audit, bench, methods, timings) if audit else [],
        "stability": stability(audit) if audit else {},
        "refracted": refracted(audit) if audit else [],
        "crack_maps": crack_maps(cm, cm_dir) if cm else [],
        "crack_meshes": cm["meshes"] if cm else [],
        "crack_legend": cm["legend"] if cm else "",
        "optimisations": optimisations(bench) if bench else None,
        "peers": peers(bench) if bench else None,
        "images": images(ctx.get("compare", [])),
        "golden": golden,
        "machine": mach,
        "bench": bench,
        "bench_runs": [{k: v for k, v in r.items() if k != "context"} for r in bench["runs"]] if bench else [],
        "kernel_hit_rate": perf.kernel_hit_rate(bench) if bench else {},
        "tracers": tracers_report.summary(audit),
    }
    charts = {
        "speed_accuracy": chart_speed_accuracy(rep["speed_accuracy"], methods, bench is not None or bool(timings)),
        "stability": chart_stability(rep["stability"], methods),
        "crack_leaks": chart_crack_leaks(rep["crack_maps"], methods) if rep["crack_maps"] else None,
        "optimisations": chart_optimisations(rep["optimisations"]) if bench else [],
        "peers": chart_peers(rep["peers"]) if bench else None,
        "tracers": tracers_report.chart(rep["tracers"], svg_of),
        "kernel_hit_rate": None,
    }
    if rep["kernel_hit_rate"]:
        fig, facts = perf.chart_kernel_hit_rate(plt, rep["kernel_hit_rate"], methods, STAMP[0] + "; 4096 pairs a row")
        CHART_FACTS.extend(facts)
        charts["kernel_hit_rate"] = svg_of(fig)
    uris = {}
    for c in rep["crack_maps"]:
        uris[c["image"]] = data_uri(c["image"])
    for im in rep["images"]:
        for kind, p in im["files"].items():
            marks = [(d["x"], d["y"]) for d in im["differences"]] if kind == "diff" else ()
            uris[p] = data_uri(p, marks=marks[:50])
    text = page(rep, charts, methods, uris)
    out = ctx["out_dir"]
    with open(os.path.join(out, "index.html"), "w", errors="replace") as f:
        f.write(text)
    # Each row's figure and spread, not the combined internals.
    if bench:
        rep["bench"] = {"runs": rep.pop("bench_runs"), "used_runs": bench["used_runs"], "mode": STAMP[0],
                        "rows": [{"name": n, "metric": r["_metric"], "better": r["_better"], "flagged": r["_flagged"],
                                  "repetitions": r["_reps"]} | (r["_spread"].get(r["_metric"]) or {})
                                 for n, r in bench["rows"].items()]}
    else:
        rep.pop("bench_runs")
    rep["charts"] = CHART_FACTS
    with open(os.path.join(out, "report.json"), "w") as f:
        json.dump(finite(rep), f, indent=1, allow_nan=False, default=str)
        f.write("\n")


def one_line(text):
    return " ".join(str(text).split())[:500]


if __name__ == "__main__":
    # Never a traceback: bad input is one line naming its file and exit 2,
    # which rayaudit report passes on (an unforeseen error names the input
    # being read and the exception, still one line).
    try:
        main()
    except BadInput as e:
        sys.stderr.write(one_line(e) + "\n")
        sys.exit(2)
    except MemoryError:
        sys.stderr.write(one_line(f"{current_input[0]}: not enough memory to draw the report") + "\n")
        sys.exit(2)
    except Exception as e:  # noqa: BLE001
        sys.stderr.write(one_line(f"{current_input[0]}: cannot be used in the report: {type(e).__name__}: {e}") + "\n")
        sys.exit(2)
