"""MkDocs hooks of mjeap's site (mkdocs.yml ``hooks:``).

1. The performance tables: ``docs/performance.md`` holds the marker ``<!-- bench-tables -->``,
   which becomes the tables of the committed ``docs/bench.json`` (written by
   ``python scripts/bench.py --json docs/bench.json``). The docs build never runs the bench:
   it only reads that file. ``tables(data)`` is also what tests/test_docs.py checks.
2. Sphinx roles in docstrings (``:class:`mjeap.Scene```, ``:func:`~mjeap.rollout```) are
   shown as the code they wrap, without the role's name and the ``~``.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

MARKER = "<!-- bench-tables -->"
BENCH_JSON = Path(__file__).resolve().parent.parent / "bench.json"


def _num(x, digits=3) -> str:
    """A number with ``digits`` significant figures and thousands separated."""
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return f"{x:,}"
    x = float(x)
    if x == 0:
        return "0"
    if abs(x) >= 10 ** digits:
        return f"{x:,.0f}"
    if abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def _table(header, rows) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _machine(m) -> str:
    return (f"Python {m.get('python', '?')}, MuJoCo {m.get('mujoco', '?')}, {m.get('processor', '?')}, "
            f"{m.get('cpus', '?')} CPUs")


def _models(rows) -> str:
    return ("**models**: every shipped model file this MuJoCo loads (`mjeap.assets.path`), as a user "
            "plays it (`mjeap.load_mjcf`, MuJoCo's own stepping loop, one thread, its drive held off rest); "
            "the real-time factor is simulated seconds per wall second (below 1: slower than real time in "
            "MuJoCo's viewer).\n\n" + _table(
                ["file", "nv", "timestep (ms)", "steps/s", "real-time factor"],
                [[f"`{r.get('file', r['actuator'] + '_' + r['representation'] + '.xml')}`", r["nv"],
                  _num(1e3 * r["timestep_s"]), _num(r["steps_per_s"]), _num(r["real_time_factor"])] for r in rows]))


def _drives(rows) -> str:
    return ("**drives**: the cost of one drive step on its actuator's beam (the voltage alternating "
            "every step); open loop: the threaded engine can run it.\n\n" + _table(
                ["drive", "actuator", "segments", "step (us)", "open loop"],
                [[f"`{r['drive']}`", f"`{r['actuator']}`", r["segments"], _num(r["step_us"], 2),
                  _num(r["open_loop"])] for r in rows]))


def _threaded(d) -> str:
    rows = [["one rollout", _num(d["single_loop_s"]) + " s", _num(d["single_threaded_s"]) + " s",
             _num(d["single_loop_s"] / d["single_threaded_s"], 2) + "x"],
            ["16 rollouts, 1 thread", _num(d["batch16_loop_s"]) + " s",
             _num(d["batch16_threaded_1thread_s"]) + " s",
             _num(d["batch16_loop_s"] / d["batch16_threaded_1thread_s"], 2) + "x"],
            ["16 rollouts, 2 threads", _num(d["batch16_loop_s"]) + " s (one by one)",
             _num(d["batch16_threaded_2thread_s"]) + " s",
             _num(d["batch16_speedup_2threads_vs_loop"], 2) + "x"]]
    return (f"**threaded**: {d['case']}; {_num(d['steps'])} steps of {_num(1e6 * d['timestep_s'])} us. The loop "
            "engine against MuJoCo's `mujoco.rollout`.\n\n"
            + _table(["run", "loop", "threaded", "speed-up"], rows))


def _rollout(d) -> str:
    rows = [["wall time", _num(d["wall_time_s"]) + " s"], ["real-time factor", _num(d["real_time_factor"])],
            ["steps", _num(d["steps"])], ["timestep", _num(1e3 * d["timestep_s"]) + " ms"],
            ["drive step", _num(d["drive_step_us"], 2) + " us"], ["mj_step", _num(d["mj_step_us"], 2) + " us"],
            ["whole run, per step", _num(d["loop_us_per_step"], 2) + " us"],
            ["peak-to-peak curvature against half the step and twice the segments",
             f"{100 * d['p2p_relative_difference']:+.3f} %"]]
    return f"**rollout**: {d['case']}.\n\n" + _table(["quantity", "value"], rows)


def _sweep(d) -> str:
    m = d["memory_per_rollout"]
    rows = [["1 worker", _num(d["workers_1"]["rollouts_per_s"]), _num(d["workers_1"]["wall_s"])],
            ["2 workers", _num(d["workers_2"]["rollouts_per_s"]), _num(d["workers_2"]["wall_s"])]]
    return (f"**sweep**: {d['case']}; 2 workers give {_num(d['speedup_2_vs_1'], 2)}x one. One rollout "
            f"peaks at {_num(m['python_peak_bytes'] / 1e6, 2)} MB of Python memory "
            f"({_num(m['result_arrays_bytes'] / 1e6, 2)} MB of it results), plus "
            f"{_num(m['mjdata_bytes'] / 1e6, 2)} MB of MjData.\n\n"
            + _table(["workers", "rollouts/s", "wall (s)"], rows))


def _native(d) -> str:
    rows = [["one run", _num(d["single_loop_s"]) + " s", _num(d["single_native_s"]) + " s",
             _num(d["single_speedup_native_vs_loop"], 2) + "x"],
            ["16 runs (loop one by one, native on 2 threads)", _num(d["batch16_loop_s"]) + " s",
             _num(d["batch16_native_2threads_s"]) + " s", _num(d["batch16_throughput_native_vs_loop"], 2) + "x"],
            ["mj_step (bare beam vs native model)", _num(d["mj_step_bare_us"], 2) + " us",
             _num(d["mj_step_native_us"], 2) + " us", _num(1 / d["native_step_cost_vs_bare"], 2) + "x"],
            [f"stability map, {d['stability_map_points']} points on 2 workers (points/s)",
             _num(d["stability_map_loop_rollouts_per_s"]), _num(d["stability_map_native_rollouts_per_s"]),
             _num(d["stability_map_native_rollouts_per_s"] / d["stability_map_loop_rollouts_per_s"], 2) + "x"]]
    return f"**native**: {d['case']}.\n\n" + _table(["run", "loop", "native", "native / loop"], rows)


def _generic(name, d) -> str:
    """A section without its own table: its scalar numbers, flattened one level."""
    rows = []
    for k, v in d.items():
        if isinstance(v, dict):
            rows += [[f"{k}.{k2}", _num(v2) if isinstance(v2, (int, float)) else f"`{v2}`"]
                     for k2, v2 in v.items() if isinstance(v2, (int, float, str))]
        elif isinstance(v, (int, float)):
            rows.append([k, _num(v)])
        elif isinstance(v, str):
            rows.append([k, v])
    return f"**{name}**\n\n" + _table(["key", "value"], rows)


def _show(d) -> str:
    fresh = d.get("fresh_process", {})
    return ("**show**: `mjeap show` per file, the designer's first numbers from closed forms and the linearised "
            "model: the first call in a process and the best of three more; a fresh process runs the command in "
            f"{_num(fresh.get('command_s'))} s, of which importing the package takes {_num(fresh.get('import_s'))} s."
            "\n\n" + _table(["file", "first (s)", "again (s)"],
                             [[f"`{r['file']}`", _num(r["first_s"]), _num(r["again_s"])] for r in d.get("files", [])]))


FORMATS = {"show": _show, "models": _models, "rollout": _rollout, "drives": _drives, "threaded": _threaded, "sweep": _sweep,
           "native": _native}


def tables(data: dict) -> str:
    """Markdown for every section of a bench JSON (``scripts/bench.py --json``), in its order."""
    parts = [f"Measured on: {_machine(data.get('machine', {}))}. Sections in the file: "
             + ", ".join(f"`{k}`" for k in data if k != "machine") + "."]
    for name, d in data.items():
        if name == "machine":
            continue
        fmt = FORMATS.get(name)
        parts.append(fmt(d) if fmt else _generic(name, d) if isinstance(d, dict) else f"**{name}**: see the JSON")
    return "\n\n".join(parts)


def on_page_markdown(markdown, page, config, files):
    if MARKER not in markdown:
        return markdown
    data = json.loads(BENCH_JSON.read_text())
    return markdown.replace(MARKER, tables(data))


_ROLE = re.compile(r":(?:py:)?(?:mod|class|func|meth|attr|data|exc|obj|const):(<code>)~?")


def on_page_content(html, page, config, files):
    return _ROLE.sub(r"\1", html)
