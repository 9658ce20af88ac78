"""The exceptions focal raises: the C++ hierarchy of include/focal/core/error.h.

Each is also a subclass of the built-in exception a Python caller would catch for the same
problem, so ``except ValueError`` keeps working.
"""


class FocalError(Exception):
    """Base class of every error focal raises (C++ ``focal::Error``)."""


class InvalidInputError(FocalError, ValueError):
    """Arrays or options that violate a documented precondition: wrong shapes, face indices out
    of range, unknown option values (C++ ``focal::InvalidInput``)."""


class FocalIOError(FocalError, OSError):
    """A file could not be read or written, or its contents are malformed; the message names
    the file and, where known, the line or element (C++ ``focal::IoError``)."""


class DeviceError(FocalError, RuntimeError):
    """A GPU was asked for but is not available (C++ ``focal::DeviceError``)."""
