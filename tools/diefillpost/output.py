"""Output files that replace the old ones only once they are complete: each is
written to a temporary file in the same folder and renamed over the old one at the
end, so that an error half-way (or a tool stopped) leaves the earlier results as
they were instead of a truncated file."""
import contextlib
import os
import tempfile


@contextlib.contextmanager
def replacing(path):
    """A temporary path beside `path`; renamed to `path` when the block ends without
    an error, removed when it raises."""
    folder, name = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".writing", dir=folder)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


@contextlib.contextmanager
def open_replacing(path, mode="w", **kwargs):
    """open() for writing `path` through replacing(): the file appears, complete,
    when the block ends."""
    with replacing(path) as tmp:
        with open(tmp, mode, **kwargs) as f:
            yield f


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask
