"""What the plot scripts of experiments/plots share (imported from beside them).

pyplot(script): matplotlib's pyplot without a display (the Agg backend); when matplotlib is
missing it prints which Debian package to install and exits with status 3.
save_png(fig, path, **savefig_args): the figure as a PNG at path; write_text(path, content): a
UTF-8 text file at path. Both write under a hidden temporary name in the same folder and rename
(os.replace), so an interrupted run leaves no partial file under the final name; the figure is
closed whatever happens.

The temporary name is the one experiments/output/AtomicFile.h describes,
".<stem>.tmp-<pid>-<counter>-<host><ext>" beside the final file (<host>: 8 hex digits of the
FNV-1a hash of the host name), so that the testbed recognises a temporary left by a killed script
and removes it on its next run into that folder.
"""
import itertools
import os
import socket
import sys

_counter = itertools.count()


def pyplot(script):
    try:
        import matplotlib

        matplotlib.use("Agg")  # no display; must precede pyplot
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"{script}: matplotlib is not installed (Debian: apt-get install python3-matplotlib)",
              file=sys.stderr)
        sys.exit(3)
    return plt


def _host_tag():
    value = 2166136261
    for byte in socket.gethostname().encode("utf-8"):
        value = ((value ^ byte) * 16777619) & 0xFFFFFFFF
    return "%08x" % value


def temporary_path(path):
    directory, name = os.path.split(path)
    stem, ext = os.path.splitext(name)
    temp = ".%s.tmp-%d-%d-%s%s" % (stem, os.getpid(), next(_counter), _host_tag(), ext)
    return os.path.join(directory, temp)


def _replace_atomically(path, write):
    """Calls write(temp) and renames temp to path; removes temp if anything fails."""
    temp = temporary_path(path)
    try:
        write(temp)
        os.replace(temp, path)
    finally:
        if os.path.exists(temp):
            os.remove(temp)


def save_png(fig, path, **savefig_args):
    import matplotlib.pyplot as plt

    try:
        _replace_atomically(path, lambda temp: fig.savefig(temp, format="png", **savefig_args))
    finally:
        plt.close(fig)


def write_text(path, content):
    def write(temp):
        with open(temp, "w", encoding="utf-8") as f:
            f.write(content)

    _replace_atomically(path, write)
