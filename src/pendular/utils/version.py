"""The installed pendular's version."""


def software_version():
    """The installed pendular version (package metadata; "0+unknown" for a source tree that
    was not installed)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pendular")
    except PackageNotFoundError:
        return "0+unknown"
