"""Regenerate every figure and console output quoted in README.md and docs/*.md.

Usage::

    python benchmarks/readme_figures.py [--only TEXT] [--list] [FILE.md ...]

A quoted output is a block between two markers; the opening one names the commands::

    <!-- figures
    $ people-tracker run ../shared/data/leigh/general_tracking_moving_1.bag --tracks tracks.csv  #> tail 3
    $ people-tracker evaluate tracks.csv --ground-truth ../shared/data/leigh/general_tracking_moving_1.bag
    -->
    ```console
    (written by this script)
    ```
    <!-- /figures -->

Each command runs in a scratch folder beside the repository (so ``../shared/data`` is the
same folder it is from the repository's root, and ``benchmarks/``, ``demos/`` and
``configs/`` are linked into it), one block's commands in one folder, in order, and the
block becomes a ``console`` fence with each ``$ command`` and its output (stdout and
stderr as they came). ``#> tail N``, ``#> head N``, ``#> grep TEXT`` or ``#> grep -v TEXT`` after a command
keeps only those lines of its output (shown after ``...`` where lines were left out).
A command that fails stops the script with its output, and nothing is rewritten.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"(<!-- figures\n(?P<cmds>.*?)\n-->\n)(?P<body>.*?)(<!-- /figures -->)", re.S)
LINKED = ("benchmarks", "demos", "configs")


def _filtered(output: str, rule: str | None) -> str:
    lines = output.rstrip("\n").splitlines()
    if not rule:
        return "\n".join(lines)
    kind, _, arg = rule.strip().partition(" ")
    if kind == "tail":
        kept = lines[-int(arg):]
        return "\n".join((["..."] if len(kept) < len(lines) else []) + kept)
    if kind == "head":
        kept = lines[:int(arg)]
        return "\n".join(kept + (["..."] if len(kept) < len(lines) else []))
    if kind == "grep":
        invert = arg.startswith("-v ")
        text = arg[3:] if invert else arg
        kept = [ln for ln in lines if (text in ln) != invert]
        return "\n".join((["..."] if len(kept) < len(lines) else []) + kept)
    raise SystemExit(f"readme_figures: unknown filter '#> {rule}'")


def run_block(commands: list[str]) -> str:
    """The console text of one block: each command and its (filtered) output."""
    scratch = Path(tempfile.mkdtemp(prefix=".figures-", dir=REPO.parent))
    try:
        for name in LINKED:
            (scratch / name).symlink_to(REPO / name)
        env = dict(os.environ, COLUMNS="120", PYTHONUNBUFFERED="1")
        env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
        parts = []
        for line in commands:
            cmd, _, rule = line.partition("#>")
            cmd = cmd.strip()
            shown = cmd.replace(sys.executable, "python")
            proc = subprocess.run(cmd, shell=True, cwd=scratch, env=env, capture_output=True, text=True)
            output = proc.stdout + proc.stderr
            if proc.returncode not in (0, 2) or (proc.returncode == 2 and "error" not in output):
                raise SystemExit(f"readme_figures: '{cmd}' failed with exit status {proc.returncode}:\n{output}")
            parts.append(f"$ {shown}\n{_filtered(output, rule or None)}".rstrip())
        return "\n".join(parts)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def regenerate(path: Path, only: str | None) -> int:
    """Run the blocks of ``path`` (those with a command containing ``only``, if given) and
    write their outputs in. The file is read again before it is written, and each output
    goes to the block with its commands there: what was edited outside the blocks while the
    commands ran (they may run for an hour) is kept."""
    outputs: dict[str, str] = {}  # a block's opening marker -> its new console text
    for m in BLOCK.finditer(path.read_text(encoding="utf-8")):
        commands = [ln[2:] for ln in m.group("cmds").splitlines() if ln.startswith("$ ")]
        if (only and not any(only in c for c in commands)) or m.group(1) in outputs:
            continue
        print(f"{path.name}: {commands[0][:100]}", file=sys.stderr, flush=True)
        outputs[m.group(1)] = run_block(commands)
    if not outputs:
        return 0
    text = path.read_text(encoding="utf-8")
    found = set()

    def replace(m: re.Match) -> str:
        if m.group(1) not in outputs:
            return m.group(0)
        found.add(m.group(1))
        return f"{m.group(1)}```console\n{outputs[m.group(1)]}\n```\n{m.group(4)}"

    new = BLOCK.sub(replace, text)
    for marker in outputs.keys() - found:
        print(f"readme_figures: {path.name}: the block of '{marker.splitlines()[1][2:80]}' was edited away while "
              "its commands ran; its output is not written", file=sys.stderr)
    if new != text:
        tmp = path.with_name(f".{path.name}.figures-tmp")
        tmp.write_text(new, encoding="utf-8")
        os.replace(tmp, path)  # whole or not at all
    return len(found)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", type=Path, help="Markdown files (default: README.md and docs/*.md)")
    ap.add_argument("--only", metavar="TEXT", help="regenerate only the blocks with a command containing TEXT")
    ap.add_argument("--list", action="store_true", help="list the blocks' commands and stop")
    args = ap.parse_args(argv)
    files = args.files or [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
    if args.list:
        for f in files:
            for m in BLOCK.finditer(f.read_text(encoding="utf-8")):
                print(f"{f.name}: " + " ; ".join(ln[2:] for ln in m.group("cmds").splitlines() if ln.startswith("$ ")))
        return 0
    total = sum(regenerate(f, args.only) for f in files)
    print(f"readme_figures: {total} blocks regenerated", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
