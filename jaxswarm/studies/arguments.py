"""The command-line checks the table scripts share: counts of at least 1, comma lists of numbers
or names, and the ``--out`` folder.

A bad argument stops a script with argparse's error (exit status 2) before anything runs or is
written.
"""
from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from pathlib import Path


def add_out_argument(parser: argparse.ArgumentParser, name: str,
                     results: str | None = None) -> None:
    """Add ``--out``, the output folder: ``out/<name>`` by default; ``make reproduce`` writes
    ``results/<results>`` (``results`` defaults to ``name``)."""
    parser.add_argument("--out", type=Path, default=Path("out", name),
                        help=f"output folder (default out/{name}; make reproduce: "
                             f"results/{results or name})")


def check_counts(parser: argparse.ArgumentParser, args: argparse.Namespace,
                 *options: str) -> None:
    """Stop with the parser's error unless each of ``options`` (argparse destinations, e.g.
    ``"max_plans"`` for ``--max-plans``) is at least 1."""
    for option in options:
        value = getattr(args, option)
        if value < 1:
            parser.error(f"--{option.replace('_', '-')} must be at least 1, got {value}")


def numbers_argument(allowed: Sequence[int]) -> Callable[[str], list[int]]:
    """An argparse ``type``: a comma list of numbers from ``allowed`` (e.g. ``"4,1"``), sorted,
    repeats dropped."""
    shown = ", ".join(map(str, allowed))

    def numbers(text: str) -> list[int]:
        try:
            chosen = sorted({int(part) for part in text.split(",")})
        except ValueError:
            chosen = None
        if not chosen or not set(chosen) <= set(allowed):
            raise argparse.ArgumentTypeError(f"expected numbers from {shown}, got {text!r}")
        return chosen

    return numbers


def names_argument(known: Sequence[str]) -> Callable[[str], tuple[str, ...]]:
    """An argparse ``type``: ``"all"`` (every name of ``known``) or a comma list of names from
    ``known``, in the order given, repeats dropped."""
    def names(text: str) -> tuple[str, ...]:
        if text.strip() == "all":
            return tuple(known)
        chosen = tuple(dict.fromkeys(name.strip() for name in text.split(",") if name.strip()))
        unknown = [name for name in chosen if name not in known]
        if unknown or not chosen:
            problem = f"unknown {', '.join(unknown)}" if unknown else "no name given"
            raise argparse.ArgumentTypeError(
                f"{problem}; choose from all or {', '.join(known)}")
        return chosen

    return names
