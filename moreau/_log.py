"""Messages that are not a command's own output: the ``logging`` module, logger ``moreau``.

Every module logs to its own logger under ``moreau`` (``moreau.integrators._loops``
...). The command line shows them on stderr as ``moreau: MESSAGE``: warnings
always, INFO notes (a compile starting) on a terminal or with ``moreau -v``
(:func:`configure_cli`). A program using the package sees them as it
configures ``logging``; :func:`note` also shows an INFO note on a terminal
when nothing is configured to show it, so that an interactive first run is
not a silent wait.
"""

import logging
import sys

__all__ = ["note", "configure_cli"]

#: format of the command line's messages on stderr
CLI_FORMAT = "moreau: %(message)s"


def _shown(logger, level):
    # whether some handler on the logger's chain takes a record at this level
    if not logger.isEnabledFor(level):
        return False
    node = logger
    while node is not None:
        if any(level >= h.level for h in node.handlers):
            return True
        if not node.propagate:
            return False
        node = node.parent
    return False


def note(logger, msg, *args):
    """Log ``msg % args`` at INFO; print it on a terminal's stderr if no handler shows INFO.

    Parameters
    ----------
    logger : logging.Logger
    msg : str
        A %-format, as for :meth:`logging.Logger.info`.

    Examples
    --------
    >>> note(logging.getLogger("moreau.example"), "compiling %s", "a loop")  # not a terminal
    """
    logger.info(msg, *args)
    if not _shown(logger, logging.INFO) and sys.stderr.isatty():
        print("moreau: " + (msg % args if args else msg), file=sys.stderr, flush=True)


class _CurrentStderr(logging.StreamHandler):
    """A handler on whatever ``sys.stderr`` is at the time of each message."""

    def __init__(self):
        super().__init__(sys.stderr)

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):
        # StreamHandler sets its stream once; this one follows sys.stderr
        pass


def configure_cli(verbose=False):
    """Show the package's messages on stderr for the command line.

    Warnings and errors always; INFO notes on a terminal or when
    ``verbose``. Calling it again replaces the handler it installed.

    Examples
    --------
    >>> h = configure_cli(verbose=True)
    >>> h.level == logging.INFO
    True
    >>> logging.getLogger("moreau").removeHandler(h)
    """
    root = logging.getLogger("moreau")
    for h in list(root.handlers):
        if isinstance(h, _CurrentStderr):
            root.removeHandler(h)
    handler = _CurrentStderr()
    handler.setFormatter(logging.Formatter(CLI_FORMAT))
    level = logging.INFO if verbose or sys.stderr.isatty() else logging.WARNING
    handler.setLevel(level)
    root.addHandler(handler)
    # below the handler's level the notes are not even made into records
    root.setLevel(level)
    return handler
