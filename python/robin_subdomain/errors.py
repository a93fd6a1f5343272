"""Exceptions of the Python subdomain server, one per protocol error family.

InputError         the body definition is unusable (protocol BAD_INPUT)
SingularBodyError  the Dirichlet conditions leave a rigid motion free (SINGULAR_BODY)
RequestError       a refused request, carrying its protocol ErrorCode name
"""


class InputError(Exception):
    """A bad body definition: mesh, material, boundary name. The message names the body,
    the SetupBody field and what to change."""


class SingularBodyError(InputError):
    """The stiffness is singular: a rigid motion is not removed by the Dirichlet conditions."""


class RequestError(Exception):
    """A request the server refuses; `code` is an ErrorCode name, e.g. "INVALID_ARGUMENT"."""

    def __init__(self, code, message):
        super().__init__(message)
        self.code = code
