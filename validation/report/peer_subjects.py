# Peers as audit subjects in the report (validation/peers/: Embree, CGAL's
# Epick, POV-Ray's mesh2 test): marked as peers beside our methods in the
# speed-against-accuracy and stability sections, each with where its speed
# figure comes from. A peer has no per-test time (Embree's answer through a
# one-triangle scene times a scene commit, not its test), so its x is the
# peer bench's whole-tracer time per ray on one of the ladder's meshes,
# named in the figure's source line.
import re

# Distinct from the registry's tab10 cycle.
PEER_COLOURS = ["#8c2d04", "#00441b", "#08306b", "#7a0177", "#525252", "#b8860b"]

# Which peer bench rows time each peer's own code, preferring the bunny on
# one thread: peer name -> regular expression over the bench row names.
BENCH_ROWS = {
    "embree": r"^peer/embree/(\w+)/primary/default/threads=1$",
    "embree-robust": r"^peer/embree/(\w+)/primary/robust/threads=1$",
    "cgal-epick": r"^peer/cgal/(\w+)/primary/threads=1$",
    "pov-mesh2": r"^peer/pov/(\w+)/threads=1$",
}
POV_PIXELS = 1280 * 960  # bench/peer_pov.cpp renders the scene at this size


def register(methods, audit):
    """Teaches the report's Methods which audit subjects are peers: colour and label."""
    methods.peers = {}
    for s in audit.get("subjects", []):
        if s.get("peer") and s["method"] not in methods.peers:
            methods.peers[s["method"]] = s.get("speed_source", "")
            methods.colour[s["method"]] = PEER_COLOURS[(len(methods.peers) - 1) % len(PEER_COLOURS)]


def is_peer(methods, name):
    return name in getattr(methods, "peers", {})


def label(methods, name):
    return ("peer: " + name) if is_peer(methods, name) else methods.label(name)


def ns_per_ray(peer, rows):
    """(ns per ray, row name) from the peer bench, or (None, None)."""
    pattern = BENCH_ROWS.get(peer)
    if not pattern:
        return None, None
    found = []
    for name, b in rows.items():
        m = re.match(pattern, re.sub(r"/(real|manual)_time$", "", name))
        if not m:
            continue
        if peer == "pov-mesh2":
            if b.get("pov_trace_cpu_s"):
                found.append((m.group(1), 1e9 * float(b["pov_trace_cpu_s"]) / POV_PIXELS, name))
        elif b.get("Mrays_per_s"):
            found.append((m.group(1), 1e3 / float(b["Mrays_per_s"]), name))
    if not found:
        return None, None
    found.sort(key=lambda f: (f[0] != "bunny", f[0]))
    return found[0][1], found[0][2]


def annotate(entries, methods, rows):
    """Marks the speed-against-accuracy entries of peers and gives each its speed figure and source."""
    for e in entries:
        e["peer"] = is_peer(methods, e["method"])
        if not e["peer"]:
            continue
        ns, row = ns_per_ray(e["method"], rows)
        e["ns_per_test"] = ns
        unit = "pixel of POV-Ray's render (CPU)" if e["method"] == "pov-mesh2" else "ray of the peer's whole tracer"
        e["speed_source"] = (f"peer bench {row}: ns per {unit} (no per-test time exists)"
                             if row else "no speed figure: " + (methods.peers.get(e["method"]) or "no peer bench row"))
    return entries


CAPTION = (" Stars are peers, other projects' own code run by the audit (validation/peers/); a peer's x is its "
           "whole tracer's time per ray (POV-Ray: per pixel) from the peer bench, named in the table, as no per-test "
           "time exists.")


def legend(row):
    """One legend right of a row of panels, naming every line of any panel: a
    peer answers at one precision only, so its line is in one panel alone."""
    handles = {}
    for ax in row:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    row[-1].legend(list(handles.values()), list(handles.keys()), fontsize=6.5, loc="upper left",
                   bbox_to_anchor=(1.01, 1))
