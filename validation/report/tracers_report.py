"""The report's whole-tracer section (validation/tracers): each tracer's leaks
per million rays at every placement of the closed meshes, with Embree's verify
bar (a miss rate of 2e-5, i.e. 20 per million) drawn. Reads the audit JSON's
`tracers` key; absent, the section says how to get it."""

import matplotlib.pyplot as plt


def summary(audit):
    """Per tracer: leaks per million rays at each offset (all scales and
    shapes pooled), false hits and wrong nearest totals. None without data."""
    tr = audit.get("tracers") if isinstance(audit, dict) else None
    if not tr:
        return None
    offsets = [float(o) for o in tr["offsets"]]
    rows = []
    for name in tr["subjects"]:
        per = {}
        for c in tr["cells"]:
            if c["tracer"] != name:
                continue
            p = per.setdefault(float(c["offset"]), [0, 0])
            p[0] += int(c["leaks"])
            p[1] += int(c["rays"])
        t = tr["totals"][name]
        rows.append({
            "tracer": name,
            "leaks_per_million": [1e6 * per[o][0] / per[o][1] if o in per and per[o][1] else None for o in offsets],
            "false_hits_per_million": float(t["false_hits_per_million"]),
            "wrong_nearest_per_million": float(t["wrong_nearest_per_million"]),
            "inside_miss_rate": float(t["inside_miss_rate"]),
        })
    return {"offsets": offsets, "bar_per_million": 1e6 * float(tr["embree_miss_rate_bar"]), "rows": rows,
            "skipped": tr.get("skipped", [])}


def chart(s, svg_of):
    if not s:
        return None
    fig, ax = plt.subplots(figsize=(9, 4.8))
    xs = [max(o, 1.0) for o in s["offsets"]]  # offset 0 drawn at 1 on the log axis
    floor = 0.5  # a tracer with no leak drawn on the floor, not lost below it
    for r in s["rows"]:
        pts = [(x, max(v, floor)) for x, v in zip(xs, r["leaks_per_million"]) if v is not None]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", linewidth=1, label=r["tracer"])
    ax.axhline(s["bar_per_million"], color="red", linestyle="--", linewidth=1.5,
               label="Embree's verify bar (2e-5 = 20 per million)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("offset of the closed mesh from the origin (0 drawn at 1)")
    ax.set_ylabel("leaks per million rays (0 drawn at 0.5)")
    ax.set_title("Whole tracers: rays through closed meshes")
    ax.legend(fontsize=6, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1))
    fig.tight_layout()
    out = svg_of(fig)
    plt.close(fig)
    return out


def html(s, svg, esc, chart_html):
    h = ["<h2>Whole tracers: leaks through closed meshes</h2>"]
    if not s:
        h.append("<p>No tracer audit in this run: <code>rayaudit audit --tracers bvh,embree,embree-robust,cgal-aabb "
                 "--json FILE</code> adds it.</p>")
        return "".join(h)
    if svg:
        h.append(chart_html(svg, "Each line is a tracer: rays from inside the audit's closed meshes and from outside "
                                 "through their vertices and edges, which the exact answer sends into the solid, that "
                                 "the tracer let through, per million, at each placement (shapes and scales pooled). "
                                 "Dashed: Embree's own verify test fails above a miss rate of 2e-5."))
    h.append("<table><tr><th>tracer</th><th>false hits / M</th><th>wrong nearest / M</th>"
             "<th>inside miss rate</th></tr>")
    for r in s["rows"]:
        cls = ' class="bad"' if r["inside_miss_rate"] * 1e6 > s["bar_per_million"] else ""
        h.append(f"<tr><td>{esc(r['tracer'])}</td><td>{r['false_hits_per_million']:.1f}</td>"
                 f"<td>{r['wrong_nearest_per_million']:.1f}</td><td{cls}>{r['inside_miss_rate']:.2e}</td></tr>")
    h.append("</table>")
    if s["skipped"]:
        h.append("<p>Not judged (float cannot hold the mesh there): " +
                 ", ".join(f"offset {esc(str(k['offset']))} scale {esc(str(k['scale']))}" for k in s["skipped"]) + "</p>")
    return "".join(h)
