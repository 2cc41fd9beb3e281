"""The click options of the commands, generated from the fields of the option objects
(vampc.options): each field's `cli(...)` declaration becomes one option, so the two cannot drift, and
`build` turns the parsed values back into the option object, with the names the user gave."""
from __future__ import annotations

import enum
from dataclasses import fields

import click
from click.core import ParameterSource

from vampc.options import cli_fields, default


class FilePath(click.Path):
    """click.Path that refuses an empty name (a shell variable that was never set), rather than
    falling back on a default file or the current folder."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not value.strip():
            self.fail("an empty file name", param, ctx)
        return super().convert(value, param, ctx)


class _Plain:
    """A click number type that takes ASCII digits only, without separators (vampc.textio.
    plain_number: int() and float() also read '١٠', '６４' and '1_0')."""

    def convert(self, value, param, ctx):
        from vampc.textio import plain_number
        if isinstance(value, str) and not plain_number(value):
            self.fail(f"{value!r} is not a number written in ASCII digits", param, ctx)
        return super().convert(value, param, ctx)


class PlainInt(_Plain, click.types.IntParamType):
    pass


class PlainIntRange(_Plain, click.IntRange):
    name = "integer"      # (click's "'abc' is not a valid integer range." read as if ranges were given)


class PlainFloat(_Plain, click.types.FloatParamType):
    pass


class Choices(click.Choice):
    """A choice among names a registry gives when the command line is parsed (a layout registered
    after import is a choice)."""

    def __init__(self, names):
        self.names = names
        super().__init__(())

    @property
    def choices(self):
        return tuple(self.names())

    @choices.setter
    def choices(self, value):
        pass


def options_of(*classes, hidden=(), helps=None):
    """Decorator: one click option per field of the option classes (vampc.options). Fields named
    in `hidden` are left out of --help (a command that refuses them: they still parse, so giving
    one is that command's usage error, not click's "no such option"). `helps` gives a field this
    command's own help, as (text, click keywords over the field's: show_default=False where the
    field's default is not what this command takes)."""
    def decorate(f):
        for cls in reversed(classes):
            for fl in reversed(cli_fields(cls)):
                decls, text, kw = fl.metadata["cli"]
                kw = dict(kw)
                if helps and fl.name in helps:
                    text, own = helps[fl.name]
                    kw.update(own)
                if "choices" in kw:
                    kw["type"] = Choices(kw.pop("choices"))
                if "range" in kw:
                    kw["type"] = PlainIntRange(*kw.pop("range"))
                elif kw.get("type") is float or fl.type in (float, "float", "float | None"):
                    kw["type"] = PlainFloat()
                elif kw.get("type") is int or fl.type in (int, "int", "int | None"):
                    kw["type"] = PlainInt()
                if kw.pop("path", False):
                    kw["type"] = FilePath(dir_okay=False, allow_dash=kw.pop("dash", False))
                if fl.type in (bool, "bool") and "/" not in decls[0]:
                    kw["is_flag"] = True
                if fl.name in hidden:
                    kw["hidden"] = True
                value = default(fl)
                value = value.value if isinstance(value, enum.Enum) else value
                f = click.option(*decls, fl.name, default=value if value != () else None,
                                 help=text, **kw)(f)
        return f
    return decorate


def build(cls, ctx: click.Context, params: dict):
    """The option object of `cls` from the parsed parameters, with the names the user gave."""
    names = {fl.name for fl in fields(cls)}
    values = {k: v for k, v in params.items() if k in names}
    if "lock" in values:
        values["lock"] = tuple(values["lock"] or ())
    if "given" in names:
        values["given"] = frozenset(   # every option the user gave, this object's or not
            k for k in ctx.params if ctx.get_parameter_source(k) not in (
                None, ParameterSource.DEFAULT, ParameterSource.DEFAULT_MAP))
    if "library" in names:
        values["library"] = False      # (the command line says what was given)
    return cls(**values)
