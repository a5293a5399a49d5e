"""The one error hierarchy of assemblykit.

Every exception the library raises on purpose is an :class:`AssemblyKitError`.
Errors about what a user gave us (files, fields, features) are :class:`InputError`
and name the place at fault; the command line prints them as one line and exits 2.
Answers such as "inconsistent" or "infeasible" are *not* errors: they are results.
"""

from __future__ import annotations


class AssemblyKitError(Exception):
    """Base class of every error raised by assemblykit."""


class InputError(AssemblyKitError):
    """Bad input: the message names the file, line, field or feature at fault.

    ``source`` is the file (or ``None`` for in-memory input) and ``where`` a
    location inside it: a line/column, a field path such as ``bodies.peg.features.shaft``
    or a feature name.
    """

    def __init__(self, message: str, *, source: str | None = None, where: str | None = None):
        self.source = source
        self.where = where
        self.detail = message
        prefix = ": ".join(p for p in (source, where) if p)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class SchemaError(InputError):
    """A task, problem or manifest file does not follow its schema (field path in ``where``)."""


class TaskSyntaxError(InputError):
    """A ``.rapt`` text does not parse; ``where`` is ``line L, column C``."""

    def __init__(self, message: str, *, source: str | None = None, line: int, column: int):
        self.line = line
        self.column = column
        super().__init__(message, source=source, where=f"line {line}, column {column}")


class FeatureError(InputError):
    """A feature is malformed (zero normal, negative radius, ...) or misused by a relation."""


class UnknownNameError(InputError):
    """A name refers to a body, feature or part that does not exist."""


class GeometryError(InputError):
    """A mesh or CAD file cannot be read or repaired (missing file, NaN vertices, ...)."""


class MissingExtraError(AssemblyKitError):
    """An optional dependency is needed; the message names the extra to install."""

    def __init__(self, package: str, extra: str, purpose: str):
        self.package = package
        self.extra = extra
        super().__init__(
            f"{purpose} needs the optional package '{package}': "
            f"install it with  pip install 'assemblykit[{extra}]'"
        )


class NumericError(AssemblyKitError):
    """A numeric procedure failed in a way that is not an answer (e.g. a degenerate frame)."""


class GroupError(AssemblyKitError):
    """Elements given as a symmetry group do not form one (not closed, or not normalising G0)."""
