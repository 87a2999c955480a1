"""docs/cli.md is generated from the commands' parsers, and so from each run's declared
options: a hand edit of the page, or an option declared without the page regenerated, fails."""

from pathlib import Path

from reflector_opt.cli import build_parser
from reflector_opt.cli._reference import cli_reference
from reflector_opt.util._declared import fields

PAGE = Path(__file__).resolve().parents[2] / "docs" / "cli.md"


def test_the_reference_page_is_the_generated_one():
    """Regenerate with ``python -m reflector_opt.cli._reference docs/cli.md``."""
    assert PAGE.read_text(encoding="utf-8") == cli_reference()


def test_every_declared_option_is_on_the_page_and_in_its_commands_help():
    """Each run's declaration reaches its command: the option's spelling and its help are in
    the command's ``--help`` and in its section of the page."""
    page = PAGE.read_text(encoding="utf-8")
    parser = build_parser()
    checked = 0
    for name, command in parser.commands.items():
        section = page.split(f"\n## {name}\n", 1)[1].split("\n## ", 1)[0]
        kinds = {a.declared_kind for a in command._actions if hasattr(a, "declared_kind")}
        for kind in kinds:
            for field in fields(kind):
                assert field.flag in command.format_help()
                assert f"`{field.flag}" in section
                assert " ".join(field.help.replace("|", "\\|").split()) in section
                checked += 1
    assert checked > 100  # every command's options, not a few
