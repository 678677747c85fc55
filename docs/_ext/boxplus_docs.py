"""Sphinx directives that take the documentation from the code, so it cannot drift.

* ``.. command-help:: boxplus-g2o`` — the tool's own ``--help``, run at build time
  (the installed tool beside the interpreter, else on PATH).
* ``.. cpp-headers::`` — every public C++ header under ``cpp/include/boxplus`` with the
  comment that opens it (the header comment is the API documentation of the C++
  library: layout, formulas, frames, units).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive

ROOT = Path(__file__).resolve().parents[2]


def _tool(name: str) -> str:
    beside = Path(sys.executable).parent / name
    if beside.exists():
        return str(beside)
    found = shutil.which(name)
    if found is None:
        raise RuntimeError(f"command-help: '{name}' is not installed (make install)")
    return found


class CommandHelp(Directive):
    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        env = {**os.environ, "COLUMNS": "100"}
        r = subprocess.run([_tool(self.arguments[0]), "--help"], capture_output=True, text=True,
                           timeout=120, env=env)
        if r.returncode != 0:
            raise self.error(f"{self.arguments[0]} --help exited {r.returncode}: {r.stderr[-500:]}")
        return [nodes.literal_block(r.stdout, r.stdout)]


def _leading_comment(path: Path) -> str:
    lines = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("//"):
            lines.append(line[3:] if line.startswith("// ") else line[2:])
        elif lines or line.strip():
            break
    return "\n".join(lines).strip()


class CppHeaders(Directive):
    def run(self) -> list[nodes.Node]:
        base = ROOT / "cpp" / "include"
        out: list[nodes.Node] = []
        for h in sorted((base / "boxplus").rglob("*.h")):
            rel = h.relative_to(base).as_posix()
            section = nodes.section(ids=[nodes.make_id(rel)])
            section += nodes.title(text=f"<{rel}>")
            text = _leading_comment(h) or "(no header comment)"
            section += nodes.literal_block(text, text)
            out.append(section)
        return out


def setup(app):  # noqa: ANN001, ANN201 - Sphinx's extension hook
    app.add_directive("command-help", CommandHelp)
    app.add_directive("cpp-headers", CppHeaders)
    return {"version": "1", "parallel_read_safe": True}
