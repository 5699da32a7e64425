"""What the plot scripts of experiments/plots share (imported from beside them).

pyplot(script): matplotlib's pyplot without a display (the Agg backend); when matplotlib is
missing it prints which Debian package to install and exits with status 3.
save_png(fig, path, **savefig_args): the figure as a PNG at path, written under a hidden
temporary name in the same folder and renamed (os.replace), so an interrupted run leaves no
partial file; the figure is closed whatever happens.
"""
import os
import sys


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


def save_png(fig, path, **savefig_args):
    import matplotlib.pyplot as plt

    directory, name = os.path.split(path)
    temp = os.path.join(directory, ".%s.tmp-%d.png" % (os.path.splitext(name)[0], os.getpid()))
    try:
        fig.savefig(temp, format="png", **savefig_args)
        os.replace(temp, path)
    finally:
        plt.close(fig)
        if os.path.exists(temp):
            os.remove(temp)
