"""Errors caused by the user's input: shown as one clear line, never as a traceback."""


class UserError(Exception):
    """Bad input from the user (file, field, value): the message says which and why."""
