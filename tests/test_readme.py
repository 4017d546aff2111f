"""What the README shows exists: every people-tracker command and option it quotes is in that
command's --help, and every script it names is in the repository."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests_helpers import run_cli

REPO = Path(__file__).resolve().parents[1]
DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def _commands() -> list[tuple[str, str, str]]:
    """(file, subcommand, options) of every people-tracker call in a code block or inline code."""
    out = []
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S) + re.findall(r"`([^`\n]+)`", text):
            for line in block.splitlines():
                for call in re.findall(r"people-tracker((?:\s+[^\s&|;`]+)*)", line):
                    words = call.split()
                    if words and not words[0].startswith("-") and re.fullmatch(r"[a-z][a-z0-9-]*", words[0]):
                        out.append((doc.name, words[0], " ".join(w for w in words[1:] if w.startswith("--"))))
    return out


COMMANDS = _commands()


def test_the_readme_shows_the_commands():
    assert {c for _, c, _ in COMMANDS} >= {"run", "evaluate", "simulate", "bench", "train-legs", "ros2", "replay"}


@pytest.fixture(scope="module")
def helps():
    return {c: run_cli(c, "--help").stdout for c in {c for _, c, _ in COMMANDS}}


@pytest.mark.parametrize("doc, command, options", COMMANDS)
def test_every_command_and_option_exists(doc, command, options, helps):
    assert helps[command], f"{doc}: 'people-tracker {command}' is not a command"
    for option in options.split():
        name = option.split("=")[0]
        assert re.search(rf"(^|[\s,\[]){re.escape(name)}\b", helps[command]), f"{doc}: {command} has no {name}"


def test_every_script_named_exists():
    for doc in DOCS:
        for script in re.findall(r"python (benchmarks/\w+\.py|demos/\w+\.py)", doc.read_text(encoding="utf-8")):
            assert (REPO / script).is_file(), f"{doc.name} names {script}"


def test_every_option_mentioned_exists_somewhere(helps):
    known = " ".join(helps.values()) + run_cli("--help").stdout
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        for code in re.findall(r"`([^`\n]+)`", text) + re.findall(r"```[a-z]*\n(.*?)```", text, re.S):
            for option in re.findall(r"(?<![\w-])(--[a-z][a-z-]+)", code):
                if option == "--help" or any(w in code for w in ("pip ", "pytest", "python ")):
                    continue
                assert re.search(rf"(^|[\s,\[]){re.escape(option)}\b", known), f"{doc.name}: no command has {option}"


def test_figures_keep_what_was_edited_while_their_commands_ran(tmp_path):
    """benchmarks/readme_figures.py runs a block's commands (up to an hour for all of them)
    and then writes the output in; an edit made to the page meanwhile, outside the blocks, is
    kept (it used to be overwritten by the page as it was read at the start)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("readme_figures", REPO / "benchmarks" / "readme_figures.py")
    figures = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(figures)
    page = tmp_path / "page.md"
    # the block's command edits the page above the block, as someone would while it runs
    edit = f"sed -i 's/^Before.$/Before, edited./' {page}"
    page.write_text(f"Before.\n\n<!-- figures\n$ {edit}\n$ echo hello\n-->\n```console\nold\n```\n"
                    "<!-- /figures -->\n\nAfter.\n", encoding="utf-8")
    assert figures.regenerate(page, None) == 1
    text = page.read_text(encoding="utf-8")
    assert text.startswith("Before, edited.\n")
    assert "```console\n$ " + edit + "\n$ echo hello\nhello\n```\n<!-- /figures -->\n\nAfter.\n" in text
    assert "old" not in text
