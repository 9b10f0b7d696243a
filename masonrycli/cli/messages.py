"""How the command line talks: two consoles that never parse markup, one-line errors and warnings, the
decorator that turns bad input into exit code 2, and click's usage errors as one line."""

from __future__ import annotations

import functools
import os
import sys
import warnings
from dataclasses import fields

import typer
import typer.core
from rich.console import Console
from rich.text import Text
from typer._click import core as click_core  # typer 0.29 vendors click; no public name
from typer._click import exceptions as click_errors

from geometry_library.blocks import GeometryError
from geometry_library.values import unit_hint, unit_of
from masonrycli.errors import EXIT_BAD_INPUT, EXIT_OUTPUT_FAILED, InputError, RecordWarning

# No markup and no highlighting: file names, TOML tables ("[run]") and values ("[inf, 0, 0]") print as given.
console = Console(markup=False, highlight=False)
err_console = Console(stderr=True, markup=False, highlight=False)


def say(label: str, style: str, message: str) -> None:
    """The one place messages go to stderr: ``label: message`` on one line, the message never parsed."""
    err_console.print(Text.assemble((f"{label}:", style), " ", message), soft_wrap=True)


def warn(message: str) -> None:
    say("warning", "yellow", message)


def fail(message: str, code: int = EXIT_BAD_INPUT) -> None:
    say("error", "bold red", message)
    raise typer.Exit(code)


def user_errors(func):
    """Turn bad input into one line on stderr and exit code 2, and a Ctrl-C that reaches here into one line
    and exit 130 — never a traceback."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        try:
            with warnings.catch_warnings():  # restores showwarning on the way out
                warnings.simplefilter("always", RecordWarning)
                warnings.showwarning = _show_warning(warnings.showwarning)
                return func(*args, **kwargs)
        except (InputError, GeometryError) as exc:
            fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        except BrokenPipeError:
            # the reader of stdout went away (`masonry limit arch --json | head -c 100`): not bad input;
            # click stops quietly with exit 1, as it does when the pipe breaks outside a command
            raise
        except OSError as exc:
            if getattr(exc, "output", None):  # an output being written (outputs.files.written_whole)
                fail(f"cannot write {exc.output}: {exc.strerror or exc}", EXIT_OUTPUT_FAILED)
            fail(f"{exc.filename or ''}: {exc.strerror or exc}".lstrip(": "))
        except KeyboardInterrupt:
            # Ctrl-C before a command's own handling takes over (building the structure, reading a record,
            # the LP): typer turned it into exit 130 without a word. Files are written whole or not at all.
            fail("Ctrl-C: stopped before any output was written", 130)

    return wrapper


def _show_warning(previous):
    """A ``warnings.showwarning`` that prints a :class:`RecordWarning` as one ``warning: …`` line (Python's
    own format added the file and line of the reader's source) and leaves the others to ``previous``."""

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, RecordWarning):
            warn(str(message))
        else:
            previous(message, category, filename, lineno, file, line)

    return show


def _no_type_on_flags(command, help_names: list[str]) -> None:
    """--help showed every on/off option with a type, "--no-recording <bool>" (typer 0.29), and a class
    typed "--no-recording true": a flag takes no value, so it shows none. The help option too ("--help -h
    <bool>" on every page): click makes it only when a page is shown, so it is made here, once per command,
    with the names the command line uses (click keeps the first one made)."""
    help_option = command.get_help_option(click_core.Context(command, help_option_names=help_names))
    for param in [*getattr(command, "params", []), *([help_option] if help_option is not None else [])]:
        if getattr(param, "is_flag", False) and param.metavar is None:
            param.metavar = ""
    for sub in getattr(command, "commands", {}).values():
        _no_type_on_flags(sub, help_names)


class OneLineUsageErrors(typer.core.TyperGroup):
    """Click's usage errors (``--dt abc``, an unknown option) as one line and exit code 2, like every
    other bad input, instead of a framed panel."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        _no_type_on_flags(self, self.context_settings.get("help_option_names", ["--help"]))
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        repeated = self._repeated_option(sys.argv[1:] if args is None else list(args))
        if repeated:
            say("error", "bold red", repeated)
            sys.exit(EXIT_BAD_INPUT)
        try:
            code = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except click_errors.NoArgsIsHelpError as exc:
            console.print(exc.ctx.get_help(), markup=True)
            sys.exit(exc.exit_code)  # as click and typer do
        except click_errors.UsageError as exc:
            command = exc.ctx.command_path if exc.ctx is not None else self._path_of(args)
            listed = "commands" if exc.format_message().startswith("No such command") else "options"
            said = (
                _number_with_unit(exc)
                or _sweep_axis(exc, command)
                or _split_word(exc, command)
                or f"{exc.format_message()} ({command} --help lists the {listed})"
            )
            say("error", "bold red", said)
            sys.exit(exc.exit_code)
        except click_errors.ClickException as exc:
            say("error", "bold red", exc.format_message())
            sys.exit(exc.exit_code)
        sys.exit(code if isinstance(code, int) else 0)

    # A Ctrl-C while the arguments are read (the command's own handling, user_errors, has not begun): typer
    # made it exit 130 without a word (1 in 10 tries at 0.39 s into `masonry sweep …`). Nothing is written yet.
    def make_context(self, *args, **kwargs):
        try:
            return super().make_context(*args, **kwargs)
        except KeyboardInterrupt:
            fail("Ctrl-C: stopped before any output was written", 130)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:  # a subcommand's arguments; a command's own stop never comes out as one
            fail("Ctrl-C: stopped before any output was written", 130)

    def _repeated_option(self, args: list[str]) -> str | None:
        """``--amp: given twice (0.5, then 1): give it once`` for an option of one value given twice: click
        kept the last without a word (``simulate wall --amp 0.5 … --amp 1``, a command edited from the
        history, ran at 1 m/s). Options given many times on purpose (``--param``, ``--records``) and flags
        are left alone."""
        group, rest = self, [str(a) for a in args]
        while rest and isinstance(getattr(group, "commands", None), dict) and rest[0] in group.commands:
            group = group.commands[rest.pop(0)]
        options = {
            name: p
            for p in getattr(group, "params", [])
            if getattr(p, "param_type_name", "") == "option" and not p.multiple and not p.is_flag and not p.count
            for name in (*p.opts, *p.secondary_opts)
        }
        seen: dict[str, str] = {}
        for k, arg in enumerate(rest):
            if arg == "--":
                break
            name, eq, inline = arg.partition("=")
            param = options.get(name)
            if param is None:
                continue
            if not eq and k + 1 == len(rest):  # no value: click's "Option '--dt' requires an argument"
                break
            value = inline if eq else rest[k + 1]
            if param.name in seen:
                return f"{name}: given twice ({seen[param.name]}, then {value}): give it once"
            seen[param.name] = value
        return None

    def _path_of(self, args) -> str:
        """The command line's command (``masonry simulate wall``) for an error raised without its context:
        the parser's "Option '--duration' requires an argument" pointed to ``masonry --help``, which lists
        no --duration."""
        path, group = ["masonry"], self
        for arg in sys.argv[1:] if args is None else args:
            command = getattr(group, "commands", {}).get(arg)  # a group's subcommands; a command has none
            if command is None:
                break
            path.append(arg)
            group = command
        return " ".join(path)


def _number_with_unit(exc) -> str | None:
    """``--dt 20ms: must be a number (it is read in s: convert 20 ms to s and write the number alone)`` for
    a numeric option given a number and a unit ("1s", "20 ms", "0.5m/s"), ``--dt abc: must be a number`` for
    other text, in place of the parser's "Invalid value for '--dt': Input should be a valid number"; None for
    any other usage error."""
    param, cause = getattr(exc, "param", None), exc.__cause__
    try:
        first = cause.errors()[0]  # typer converts through pydantic: the value as typed is kept there
    except (AttributeError, IndexError, TypeError):
        return None
    kind = {"float_parsing": "a number", "int_parsing": "an integer"}.get(first.get("type"))
    text = first.get("input")
    if param is None or kind is None or not isinstance(text, str):
        return None
    try:  # "--blocks 51.5": a number, not a whole one; "(write 51.5, without quotes)" read a quote never typed
        float(text)
        hint = " (an underscore is not a digit separator here)" if "_" in text else ""
    except ValueError:
        hint = unit_hint(text, unit_of(param.name))
    shown = text.strip()
    if not shown.isprintable():  # "--dt $'1\nx'" printed two lines
        shown = shown.encode("unicode_escape").decode("ascii")
    return f"{max(param.opts, key=len)} {shown}: must be {kind}{hint}"


_RECORD_SUFFIXES = (".at2", ".csv", ".txt", ".asc", ".dat")  # what --record reads (records/read.py)
_FLAG_VALUES = frozenset("true false yes no on off 1 0".split())
_UNIT_WORDS = frozenset("s ms min m mm cm m/s m/s2 m/s² cm/s mm/s g gal hz Hz kg kg/m3 kg/m³ rad deg ° %".split())


def _sweep_axis(exc, command: str) -> str | None:
    """``masonry sweep wall --courses 15``: a setting simulate takes as an option is an axis of a study, given by
    ``--param`` (one value, the same for every run). It said "No such option: --courses (Possible options:
    --force, --records)", which pointed away from it. None for any other error or option."""
    name = getattr(exc, "option_name", None) or ""
    if not (command.split()[-1:] == ["sweep"] and name.startswith("--")):
        return None
    from geometry_library.builders import BUILDERS
    from masonrycli.study.axes import MOTION_PARAMS, PGA_PARAM, RUN_PARAMS

    key = {"pga": PGA_PARAM}.get(name[2:].replace("-", "_"), name[2:].replace("-", "_"))  # simulate --pga: in g
    axes = {*MOTION_PARAMS, *RUN_PARAMS, "friction", PGA_PARAM} | {f.name for b in BUILDERS.values() for f in fields(b)}
    if key not in axes:
        return None
    return (
        f"{name}: a study takes it as an axis: --param {key}=VALUE (one value: every run; LO:HI:N or a,b,c: a "
        f"value a run; {command} --help)"
    )


def _split_word(exc, command: str) -> str | None:
    """What an extra word on the command line most likely is: a unit after a number (``--amp 1.5 m/s``) or the
    rest of a file name with a space (``masonry run my wall.toml``: "C:\\Users\\Ana Silva\\…" on a student's
    laptop), which said only "Got unexpected extra argument(s) (wall.toml)"; None for anything else."""
    message = exc.format_message()
    extra = message.removeprefix("Got unexpected extra argument").removeprefix("s").removeprefix("(s)").strip()
    if extra == message.strip() or not (extra.startswith("(") and extra.endswith(")")) or exc.ctx is None:
        return None
    words = extra[1:-1]
    if not words.strip():  # "masonry simulate wall ''" (an unset "$OPTS" quoted) was an IndexError, exit 1
        return f"{message}: an empty word — a shell variable with nothing in it? ({command} --help)"
    pga = exc.ctx.params.get("pga")
    if pga is not None and words.split()[0].lower() in ("g", "gal", "m/s2", "m/s²", "cm/s2", "cm/s²"):
        # "--pga 0.25 g": --pga is in g, and reads a unit joined to its number; "the options are in SI" was wrong
        return f"{message}: --pga takes its unit joined to the number (--pga {getattr(pga, 'text', pga)}{words.split()[0]}), or the number alone in g"
    if words.split()[0] in _UNIT_WORDS:
        return f"{message}: a number goes alone, without its unit (the options are in SI units: {command} --help)"
    # "--param amp=0.5, 1": a list cut at the space after its comma (it was read as a flag's value, "1")
    values = [v for value in exc.ctx.params.values() for v in (value if isinstance(value, list | tuple) else [value])]
    cut = [v for v in values if isinstance(v, str) and v.endswith(",")]
    if cut:
        return f"{message}: a list goes without spaces after its commas: {cut[-1]}{words.replace(' ', '')}"
    flags = [p for p in exc.ctx.command.params if getattr(p, "is_flag", False) and p.name in exc.ctx.params]
    given_flag = any(exc.ctx.params[p.name] != p.default for p in flags)
    if given_flag and words.split()[0].lower() in _FLAG_VALUES:  # --help showed "--no-recording <bool>"
        return f"{message}: an on/off option (--no-recording, --force) takes no value: give it alone, or leave it out"
    named = [p for p in exc.ctx.command.params if p.param_type_name == "argument"]
    given = exc.ctx.params.get(named[0].name) if named else None
    if not isinstance(given, (str, os.PathLike)):
        return None
    from masonrycli.records.knet import KNET_SUFFIXES
    from masonrycli.scenario.target import is_built_in

    given = os.fspath(given)
    joined = f"{given} {words}"
    # "masonry run wall quake.AT2" (a record without --record): "wall" is whole, no name cut at a space
    if os.path.exists(joined) or not (os.path.exists(given) or is_built_in(given)):
        return f'{message}: a name with spaces goes between quotes: {command} "{joined}"'
    record = os.path.splitext(words)[1].lower() in _RECORD_SUFFIXES or words.lower().endswith(KNET_SUFFIXES)
    if record and " " not in words and any("--record" in p.opts for p in exc.ctx.command.params):
        return f"{message}: {command} takes one structure; a record goes after --record: {command} {given} --record {words}"
    return None
