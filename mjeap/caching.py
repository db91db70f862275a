"""Bounded caches of built things (layouts, analyses, scenes, compiled models' checks), one
mechanism for all, and one :func:`clear_caches` that empties them (a benchmark's cold start).

A :class:`BoundedCache` keeps its entries in least-recently-used order and drops the oldest
past ``max_entries`` entries or ``max_bytes`` bytes (each entry's size from ``nbytes``,
counted once when it is put). An entry may belong to an ``owner``, an object its key names
by identity: the entry holds the owner, so the owner's ``id`` is not reused while the entry
lives, and an entry whose owner is another object (an ``id`` reused after the first died) is
a miss. ``locked`` guards every access with a lock (a cache threads share); ``per_thread``
keeps one store per thread (entries that hold a thread's mutable state, such as a scene's
``MjData``). :func:`clear_caches` reaches every thread's store: each finds itself cleared on
its next access.
"""
from __future__ import annotations

import threading
from collections import OrderedDict
from contextlib import nullcontext
from typing import Any, Callable, Hashable, List, Optional

__all__ = ["BoundedCache", "clear_caches", "caches"]

_REGISTRY: List["BoundedCache"] = []
_REGISTRY_LOCK = threading.Lock()


class _Store:
    """One store: the entries (key -> (owner, value, bytes)), their bytes, the generation it
    was last cleared at."""

    __slots__ = ("entries", "bytes", "generation")

    def __init__(self, generation: int):
        self.entries: "OrderedDict[Hashable, tuple]" = OrderedDict()
        self.bytes = 0
        self.generation = generation


class BoundedCache:
    """A named, bounded least-recently-used cache (see the module): ``get``, ``put``,
    ``get_or_build``, ``clear``; registered for :func:`clear_caches`."""

    def __init__(self, name: str, *, max_entries: int, max_bytes: Optional[int] = None,
                 nbytes: Optional[Callable[[Any], int]] = None, locked: bool = False, per_thread: bool = False):
        if max_entries < 1:
            raise ValueError(f"max_entries of cache {name!r} must be at least 1, not {max_entries}")
        if max_bytes is not None and nbytes is None:
            raise ValueError(f"cache {name!r}: max_bytes needs nbytes, the size of an entry")
        self.name, self.max_entries, self.max_bytes, self.nbytes = name, max_entries, max_bytes, nbytes
        self.per_thread = per_thread
        self._lock = threading.Lock() if locked else nullcontext()
        self._generation = 0
        self._local = threading.local() if per_thread else None
        self._store = None if per_thread else _Store(0)
        with _REGISTRY_LOCK:
            _REGISTRY.append(self)

    # ------------------------------------------------------------------ the store
    def _current(self) -> _Store:
        store = self._store if self._local is None else getattr(self._local, "store", None)
        if store is None:
            store = self._local.store = _Store(self._generation)
        elif store.generation != self._generation:      # cleared since this thread last looked
            store.entries.clear()
            store.bytes, store.generation = 0, self._generation
        return store

    @staticmethod
    def _key(key: Hashable, owner) -> Hashable:
        return key if owner is None else (id(owner), key)

    # ------------------------------------------------------------------ access
    def get(self, key: Hashable, owner=None, default=None):
        """The value kept under ``key`` (and ``owner``, by identity), made the most recent;
        ``default`` where there is none."""
        with self._lock:
            store = self._current()
            k = self._key(key, owner)
            hit = store.entries.get(k)
            if hit is None or hit[0] is not owner:
                return default
            store.entries.move_to_end(k)
            return hit[1]

    def put(self, key: Hashable, value, owner=None):
        """Keep ``value`` under ``key`` (and ``owner``), the oldest dropped past the bounds
        (the newest entry always stays); returns ``value``."""
        size = self.nbytes(value) if self.nbytes is not None else 0
        with self._lock:
            store = self._current()
            k = self._key(key, owner)
            old = store.entries.pop(k, None)
            if old is not None:
                store.bytes -= old[2]
            store.entries[k] = (owner, value, size)
            store.bytes += size
            while len(store.entries) > 1 and (len(store.entries) > self.max_entries or
                                              (self.max_bytes is not None and store.bytes > self.max_bytes)):
                store.bytes -= store.entries.popitem(last=False)[1][2]
        return value

    def get_or_build(self, key: Hashable, build: Callable[[], Any], *, owner=None,
                     valid: Optional[Callable[[Any], bool]] = None):
        """The value under ``key`` (and ``owner``) where it is kept and ``valid(value)``
        (default: always); else ``build()``, kept."""
        _missing = self
        hit = self.get(key, owner, _missing)
        if hit is not _missing and (valid is None or valid(hit)):
            return hit
        return self.put(key, build(), owner)

    def clear(self) -> None:
        """Forget every entry, in every thread's store."""
        with self._lock:
            self._generation += 1
            if self._store is not None:
                self._store = _Store(self._generation)

    def __len__(self) -> int:
        with self._lock:
            return len(self._current().entries)

    def __repr__(self) -> str:
        return (f"BoundedCache({self.name!r}, max_entries={self.max_entries}, max_bytes={self.max_bytes}, "
                f"per_thread={self.per_thread})")


def caches() -> List[BoundedCache]:
    """Every cache made (in the order they were made)."""
    with _REGISTRY_LOCK:
        return list(_REGISTRY)


def clear_caches() -> None:
    """Empty every cache (:func:`caches`), every thread's store included."""
    for cache in caches():
        cache.clear()
