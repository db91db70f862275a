"""The documentation's promises that a test can hold (the docs issue): the README is a front
page of at most 150 lines whose two commands CI runs, the site's generated performance tables
render from the committed bench JSON, every page the site names exists, and every test file
belongs to a layer (tests/conftest.py, docs/testing.md). ``mkdocs build --strict`` itself runs
in CI (.ci/run)."""
import importlib
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
CI = (ROOT / ".ci" / "run").read_text()
TEST_COMMAND = 'python -m pytest -q -m "not slow"'


def _bash_blocks(text):
    return re.findall(r"```bash\n(.*?)```", text, flags=re.S)


def test_readme_is_a_front_page():
    assert len(README.splitlines()) <= 150
    blocks = [b.strip() for b in _bash_blocks(README)]
    install = [b for b in blocks if b.startswith("python3 -m venv") and "mjeap rollout" in b and "--rrd" in b]
    assert install, "the README's first command installs and runs the main job with a recording"
    assert TEST_COMMAND in blocks, "the README's test command"


def test_ci_runs_the_readme_commands_and_the_docs():
    lines = [ln.strip() for ln in CI.splitlines() if not ln.strip().startswith("#")]
    assert TEST_COMMAND in lines
    # the whole suite on MuJoCo 4 (the quick loop, then the slow rest); on 3.17 the quick loop
    # and every test of the cable and of dm_control
    assert 'python -m pytest -q -m slow' in lines and lines.index('python -m pytest -q -m slow') > lines.index(TEST_COMMAND)
    on_3 = 'python -m pytest -q -m "not slow or cable or dm_control"'
    assert on_3 in lines and lines.index(on_3) > lines.index('python -m pip install -q "mujoco==3.17.0"')
    assert any('-e ".[docs]"' in ln for ln in lines)
    assert any(ln.endswith("mkdocs build --strict") for ln in lines)


def _hook():
    """The site's MkDocs hook (docs/hooks/bench_tables.py, not a script): mkdocs loads it by
    path, the test from its folder."""
    folder = str(ROOT / "docs" / "hooks")
    if folder not in sys.path:
        sys.path.insert(0, folder)
    return importlib.import_module("bench_tables")


def test_performance_tables_render_from_the_committed_bench():
    hook = _hook()
    data = json.loads(hook.BENCH_JSON.read_text())
    sections = [k for k in data if k != "machine"]
    assert sections, "docs/bench.json holds at least one section of scripts/bench.py --json"
    page = (ROOT / "docs" / "performance.md").read_text()
    assert hook.MARKER in page
    text = hook.on_page_markdown(page, None, None, None)
    assert hook.MARKER not in text
    for name in sections:
        assert f"**{name}**" in text
    if "drives" in data:
        for row in data["drives"]:
            assert f"`{row['drive']}`" in text


def test_sphinx_roles_render_as_code():
    hook = _hook()
    html = "see :class:<code>~mjeap.Scene</code> and :func:<code>mjeap.rollout</code>"
    assert hook.on_page_content(html, None, None, None) == "see <code>mjeap.Scene</code> and <code>mjeap.rollout</code>"


def test_every_page_in_the_nav_exists():
    nav = (ROOT / "mkdocs.yml").read_text().split("\nnav:", 1)[1]
    pages = re.findall(r":\s*([\w./-]+\.md)\s*$", nav, flags=re.M)
    assert len(pages) > 20
    missing = [p for p in pages if not (ROOT / "docs" / p).is_file()]
    assert not missing


def test_every_test_file_has_a_layer(request):
    """Every test file sits in a layer's folder (its marker comes from there), and every
    layer has its row in docs/testing.md's table."""
    from conftest import LAYERS, layer_of
    files = sorted((ROOT / "tests").rglob("test_*.py"))
    unassigned = [str(f.relative_to(ROOT)) for f in files if layer_of(f) is None]
    assert not unassigned, f"{unassigned}: put each in one of the layer folders tests/{{{','.join(LAYERS)}}}/"
    folders = sorted(p.name for p in (ROOT / "tests").iterdir() if p.is_dir() and any(p.glob("test_*.py")))
    assert sorted(LAYERS) == folders, "tests/conftest.py's LAYERS and the test folders differ"
    table = (ROOT / "docs" / "testing.md").read_text()
    missing = [layer for layer in LAYERS if f"`tests/{layer}/`" not in table]
    assert not missing, f"{missing} not in docs/testing.md's table"


@pytest.mark.parametrize("name", ["slow"])
def test_markers_are_registered(request, name):
    assert any(m.split(":")[0].strip() == name for m in request.config.getini("markers"))


def test_the_architecture_pages_map_is_drawn_from_the_package():
    """docs/architecture.md's map lists every module of every floor with its docstring's
    first line, as scripts/architecture_page.py draws it from the package."""
    import subprocess
    p = subprocess.run([sys.executable, str(ROOT / "scripts" / "architecture_page.py"), "--check"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, "stale: run python scripts/architecture_page.py"
    text = (ROOT / "docs" / "architecture.md").read_text()
    assert "`mjeap.simulation.pipeline`" in text and "`mjeap.studies.optimize`" in text
