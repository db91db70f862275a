"""One bounded cache for everything built scenes share (issue 44, part 5): bounds by entries
and bytes, an owner held by identity, per-thread stores, and one clear_caches that empties
every cache, other threads' stores included."""
import threading

from mjeap.caching import BoundedCache, caches, clear_caches


def test_oldest_entries_go_first_past_the_entry_bound():
    c = BoundedCache("test entries", max_entries=2)
    c.put("a", 1)
    c.put("b", 2)
    assert c.get("a") == 1          # a is now the most recent
    c.put("c", 3)
    assert c.get("b") is None and c.get("a") == 1 and c.get("c") == 3


def test_the_byte_bound_counts_each_entry_once_and_keeps_the_newest():
    c = BoundedCache("test bytes", max_entries=100, max_bytes=10, nbytes=len)
    c.put("a", "xxxx")
    c.put("b", "xxxx")
    c.put("c", "xxxx")              # 12 bytes: a goes
    assert c.get("a") is None and c.get("b") == "xxxx" and len(c) == 2
    c.put("big", "x" * 50)          # larger than the bound alone: kept, the rest dropped
    assert c.get("big") == "x" * 50 and len(c) == 1


def test_an_entry_belongs_to_its_owner_by_identity():
    class Owner:
        pass
    c = BoundedCache("test owners", max_entries=8)
    a, b = Owner(), Owner()
    c.put("k", "of a", owner=a)
    assert c.get("k", owner=a) == "of a"
    assert c.get("k", owner=b) is None and c.get("k") is None
    # the entry holds its owner: its id cannot be reused by another object while it lives
    del a
    assert all(c.get("k", owner=Owner()) is None for _ in range(100))


def test_get_or_build_builds_once_and_again_when_no_longer_valid():
    c = BoundedCache("test build", max_entries=8)
    built = []

    def build():
        built.append(1)
        return {"stale": False}
    v = c.get_or_build("k", build)
    assert c.get_or_build("k", build) is v and len(built) == 1
    v["stale"] = True
    w = c.get_or_build("k", build, valid=lambda x: not x["stale"])
    assert w is not v and len(built) == 2


def test_per_thread_stores_are_separate_and_clear_caches_reaches_every_thread():
    c = BoundedCache("test threads", max_entries=8, per_thread=True)
    c.put("k", "main")
    seen, go, done = [], threading.Event(), threading.Event()

    def worker():
        seen.append(c.get("k"))             # another thread's store is its own
        c.put("k", "worker")
        go.set()
        done.wait(5)
        seen.append(c.get("k"))             # cleared from the main thread meanwhile
    t = threading.Thread(target=worker)
    t.start()
    go.wait(5)
    assert c.get("k") == "main"
    clear_caches()
    done.set()
    t.join(5)
    assert seen == [None, None] and c.get("k") is None


def test_the_package_caches_are_registered():
    import mjeap.simulation.metric_accuracy  # noqa: F401  (the chain structures)
    import mjeap.simulation.native_model  # noqa: F401
    import mjeap.simulation.scene  # noqa: F401
    names = {c.name for c in caches()}
    assert {"layouts", "beam analyses", "shared scenes", "stable native models", "chain structures"} <= names


def test_a_file_actuator_hits_the_caches_a_catalog_id_hits(tmp_path):
    """Scene.shared on an actuator file gives the same scene twice, as on a catalog id; a
    changed file is read anew."""
    from mjeap.model.catalog import CATALOG_DIR
    from mjeap.simulation.scene import Scene
    f = tmp_path / "mine.toml"
    f.write_bytes((CATALOG_DIR / "pzt-hamr-small.toml").read_bytes())
    a, b = Scene.shared(str(f)), Scene.shared(str(f))
    assert a is b and Scene.shared("pzt-hamr-small") is Scene.shared("pzt-hamr-small")
    f.write_text(f.read_text().replace('id = "pzt-hamr-small"', 'id = "mine"'))
    c = Scene.shared(str(f))
    assert c is not a and c.actuator.id == "mine"
