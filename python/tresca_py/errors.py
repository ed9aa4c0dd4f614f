"""The one exception type for bad input to the Python side (scene, expression, mesh): entry points catch
``InputError`` and exit with ``error: <message>`` instead of a traceback."""


class InputError(ValueError):
    """Invalid input; the message names the offending key, expression or file."""
