"""The reference problems carried inside the package.

``data/problems.json`` is a verbatim copy of the project's shared reference
problems: four Manakov tops (``generic``, ``physical``, ``wide``,
``near_degenerate``), each with ``a``, ``b`` and an initial state ``l0`` ordered
(l12, l13, l14, l23, l24, l34), and the benchmark set-ups.
"""

from __future__ import annotations

import json
import os
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

__all__ = ["Problem", "as_problem", "problem", "problem_names", "read_problem", "benchmark_setup"]


class Problem(NamedTuple):
    """A reference top: Manakov parameters ``a``, ``b`` (2) and initial state ``l0``.

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> p.name, p.a.shape, p.b.shape, p.l0.shape
    ('generic', (4,), (4,), (6,))
    """

    name: str
    a: np.ndarray
    b: np.ndarray
    l0: np.ndarray
    note: str


@lru_cache(maxsize=1)
def _data() -> dict[str, Any]:
    text = resources.files("manakov").joinpath("data/problems.json").read_text()
    return json.loads(text)


def problem_names() -> list[str]:
    """Names of the built-in reference tops.

    Returns
    -------
    list of str
        ``["generic", "physical", "wide", "near_degenerate"]`` in file order.

    Examples
    --------
    >>> import manakov
    >>> manakov.problem_names()
    ['generic', 'physical', 'wide', 'near_degenerate']
    """
    return list(_data()["tops"])


def problem(name: str) -> Problem:
    """Return the built-in reference top ``name`` (see :func:`problem_names`).

    Parameters
    ----------
    name : str

    Returns
    -------
    Problem
        ``(name, a, b, l0, note)``; ``a``, ``b`` of shape (4,) define ``c_ij`` by (2),
        ``l0`` of shape (6,) is ordered ``(l12, l13, l14, l23, l24, l34)``.

    Raises
    ------
    ValueError
        If there is no problem of that name.

    Examples
    --------
    >>> import manakov
    >>> p = manakov.problem("generic")
    >>> print(p.a, p.b)
    [0.3 1.1 2.  3.7] [ 0.5 -0.2  1.4  0.9]
    >>> print(p.l0)
    [ 0.8 -0.3  0.5  1.1 -0.7  0.2]
    """
    tops = _data()["tops"]
    if name not in tops:
        raise ValueError(f"unknown problem {name!r}; known: {', '.join(tops)}")
    t = tops[name]
    return Problem(
        name=name,
        a=np.array(t["a"], dtype=float),
        b=np.array(t["b"], dtype=float),
        l0=np.array(t["l0"], dtype=float),
        note=t.get("note", ""),
    )


def benchmark_setup(name: str) -> dict[str, Any]:
    """The benchmark set-up ``name`` (``"integration"`` or ``"theta"``) as a dict.

    Parameters
    ----------
    name : str

    Returns
    -------
    dict
        A copy of the set-up's entry in ``data/problems.json``.

    Raises
    ------
    ValueError
        If there is no set-up of that name.

    Examples
    --------
    >>> from manakov.problems import benchmark_setup
    >>> sorted(benchmark_setup("integration"))
    ['sample_every', 't_end', 'top']
    """
    bench = _data()["benchmark"]
    if name not in bench:
        raise ValueError(f"unknown benchmark {name!r}; known: {', '.join(bench)}")
    return dict(bench[name])


def as_problem(p: str | Problem) -> Problem:
    """``p`` as a :class:`Problem`: a built-in name (:func:`problem`) or a Problem itself.

    Raises
    ------
    ValueError
        An unknown name, or neither a name nor a Problem.

    Examples
    --------
    >>> from manakov.problems import as_problem
    >>> as_problem("physical").name
    'physical'
    """
    if isinstance(p, Problem):
        return p
    if isinstance(p, str):
        return problem(p)
    raise ValueError(f"expected a problem name or a manakov.Problem, got {p!r}")


def read_problem(path: str | os.PathLike[str], name: str | None = None) -> Problem:
    """A top and its initial state from a JSON or TOML file (by suffix; TOML needs
    Python >= 3.11 or the ``tomli`` package).

    The file holds the keys of the built-in problems (``data/problems.json``):
    either one top at the top level, ``{"a": [...], "b": [...], "l0": [...]}``
    (optionally ``"name"`` and ``"note"``), or a table of named tops under
    ``"tops"`` as in ``problems.json`` itself, from which ``name`` picks one
    (it may be left out when the table has one top)::

        # mytop.toml
        name = "mytop"
        a = [0.1, 0.9, 2.3, 3.1]
        b = [0.4, -0.6, 1.1, 2.5]
        l0 = [0.7, -0.2, 0.6, 1.0, -0.5, 0.3]

    Parameters
    ----------
    path : str or PathLike
    name : str, optional
        The top to take from a ``"tops"`` table.

    Returns
    -------
    Problem
        ``a``, ``b``, ``l0`` as float arrays (their shapes are checked by the
        functions that use them), ``name`` (the file's, the table key, or the
        file's stem), ``note``.

    Raises
    ------
    ValueError
        A suffix other than .json or .toml, a file that does not parse, a
        missing key, or an unknown or missing ``name``.
    OSError
        The file cannot be read.

    Examples
    --------
    >>> import json, os, tempfile
    >>> from manakov.problems import read_problem
    >>> path = os.path.join(tempfile.mkdtemp(), "mytop.json")
    >>> top = {"a": [0.1, 0.9, 2.3, 3.1], "b": [0.4, -0.6, 1.1, 2.5],
    ...        "l0": [0.7, -0.2, 0.6, 1, -0.5, 0.3]}
    >>> with open(path, "w") as f:
    ...     json.dump(top, f)
    ...
    >>> print(read_problem(path).l0)
    [ 0.7 -0.2  0.6  1.  -0.5  0.3]
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        if path.suffix.lower() == ".json":
            data = json.loads(text)
        elif path.suffix.lower() == ".toml":
            data = _toml(text)
        else:
            raise ValueError(f"{path}: a problem file ends in .json or .toml, got {path.suffix!r}")
    except (json.JSONDecodeError, _TomlError) as e:
        raise ValueError(f"{path} does not parse: {e}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a table of keys a, b, l0, got {type(data).__name__}")
    default = data.get("name", path.stem)
    if "tops" in data:
        tops = data["tops"]
        if not isinstance(tops, dict) or not tops:
            raise ValueError(f"{path}: 'tops' must be a non-empty table of named tops")
        if name is None:
            if len(tops) != 1:
                raise ValueError(
                    f"{path} has {len(tops)} tops ({', '.join(tops)}): name the one to use"
                )
            name = next(iter(tops))
        if name not in tops:
            raise ValueError(f"{path} has no top {name!r}; it has {', '.join(tops)}")
        data, default = tops[name], name
    elif name is not None and name != default:
        raise ValueError(f"{path} holds one top ({default!r}), not {name!r}")
    missing = [k for k in ("a", "b", "l0") if k not in data]
    if missing:
        raise ValueError(f"{path}: missing key(s) {', '.join(missing)} (the keys of problems.json)")
    try:
        a, b, l0 = (np.array(data[k], dtype=float) for k in ("a", "b", "l0"))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{path}: a, b and l0 must be lists of numbers ({e})") from None
    return Problem(name=str(default), a=a, b=b, l0=l0, note=str(data.get("note", "")))


class _TomlError(Exception):
    pass


def _toml(text: str) -> Any:
    try:
        import tomllib  # Python >= 3.11
    except ImportError:
        try:
            import tomli as tomllib  # type: ignore[no-redef,import-not-found,unused-ignore]
        except ImportError:
            raise ValueError(
                "reading TOML needs Python >= 3.11 or the tomli package; or write the file as JSON"
            ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise _TomlError(str(e)) from None
