"""shellsim: explicit dynamics of thin and thick soft-tissue shells with the 9-node
continuum-based shell element."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("shellsim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
