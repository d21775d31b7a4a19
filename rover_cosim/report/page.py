"""HTML building blocks of the report: embedded figures, tables with labelled columns and fixed
digits, provenance blocks, the page's style (readable from 1024 px: wide tables scroll)."""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

STYLE = ("body{font-family:sans-serif;font-size:15px;max-width:1000px;margin:1.5em auto;padding:0 12px;"
         "line-height:1.4}img{max-width:100%;height:auto}figure{margin:1em 0}"
         "figcaption{font-size:13px;color:#444}.scroll{overflow-x:auto;max-width:100%}"
         "table.data{border-collapse:collapse;margin:0.6em 0;font-size:13px}"
         "table.data td,table.data th{border:1px solid #bbb;padding:3px 7px;text-align:right}"
         "table.data th{background:#f2f2f2}table.data td:first-child,table.data th:first-child{text-align:left}"
         ".missing{color:#a00}.note{background:#f7f7f2;border-left:4px solid #cc9;padding:6px 10px}"
         "pre{background:#f6f6f6;padding:1em;overflow:auto;font-size:12px}")


def missing(path: Path) -> str:
    return f"<p class='missing'>{html.escape(str(path))} not produced.</p>"


def image(path: Path, caption: str) -> str:
    """The figure ``path`` embedded with its caption; only a regular file is read (a link, which
    could point at any file of the machine, is named and left out)."""
    if path.is_symlink() or (path.exists() and not path.is_file()):
        return (f"<p class='missing'>{html.escape(caption)}: {html.escape(str(path))} is not a regular file "
                "(a link or a folder): not embedded.</p>")
    if not path.exists():
        return f"<p class='missing'>{html.escape(caption)}: {html.escape(str(path))} not produced.</p>"
    data = base64.b64encode(path.read_bytes()).decode()
    return (f"<figure><img src='data:image/png;base64,{data}' alt='{html.escape(caption)}'>"
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def table(frame: pd.DataFrame, formats: Mapping[str, str] | None = None, default: str = "{:.3g}") -> str:
    """The frame as an HTML table in a scrolling box; numbers by the column's format (a str.format
    pattern), text as it is, NaN as an empty cell."""
    formats = formats or {}
    shown = frame.copy().astype(object)
    for column in frame.columns:
        pattern = formats.get(column, default)
        shown[column] = [_cell(value, pattern) for value in frame[column]]
    return ("<div class='scroll'>" + shown.to_html(index=False, border=0, classes="data", escape=True)
            + "</div>")


def _cell(value: object, pattern: str) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, float)):
        if value != value:  # NaN
            return ""
        return pattern.format(value)
    return str(value)


def read_record(path: Path) -> dict[str, Any]:
    """A JSON record of a job (a JSON object); ValueError naming the file for anything else (not
    JSON, not UTF-8, nested too deeply, an array or a number at the top)."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except RecursionError:
        raise ValueError(f"{path}: nested too deeply to be a record of this tool") from None
    if not isinstance(record, dict):
        raise ValueError(f"{path}: a JSON {type(record).__name__}: expected an object (a record of this tool)")
    return record


def provenance(path: Path) -> str:
    if not path.exists():
        return missing(path)
    record = read_record(path)
    keep = {k: record[k] for k in ("command", "created_utc", "git_commit", "versions", "parameters", "fmu_sha256",
                                   "fmus", "model_sha256", "soil", "wheel", "set", "wall_seconds", "run_wall_seconds",
                                   "sweep_wall_seconds", "runs_computed", "runs_cached", "runs_failed") if k in record}
    text = html.escape(json.dumps(keep, indent=2))
    return f"<details><summary>{html.escape(path.name)}</summary><pre>{text}</pre></details>"


def document(title: str, sections: list[str]) -> str:
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<style>{STYLE}</style></head><body>" + "\n".join(sections) + "</body></html>\n")
