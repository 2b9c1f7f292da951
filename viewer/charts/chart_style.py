"""What every bounce chart shares (imported by the plot_*.py scripts beside it)."""
import math
import os
import textwrap

import matplotlib.ticker as ticker

# Ten clearly different hues (matplotlib's tab10) and eight markers: series k takes hue k % 10 and
# marker k % 8, so no two of the first 40 series share both.
_HUES = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
         "#17becf"]
_MARKERS = ["o", "s", "D", "^", "v", "P", "X", "*"]


def series_style(k):
    """(colour, marker) of the k-th series of a chart."""
    return _HUES[k % len(_HUES)], _MARKERS[k % len(_MARKERS)]


def plain_ticks(ax):
    """Decimal tick labels (0.5, 2, 30) instead of powers of ten on log axes, with the 2s and 5s
    labelled too where the axis spans fewer than three decades, so a value like 0.48% can be read
    off against a labelled tick below 1."""

    def minor(axis):
        # Decided when drawn, once the limits are final.
        def label(v, _):
            lo, hi = axis.get_view_interval()
            if not (lo > 0 and hi > lo):
                return ""
            decades = math.log10(hi / lo)
            keep = "235" if decades < 1.5 else ("25" if decades < 3 else "")
            return f"{v:g}" if f"{v:g}".lstrip("0.")[:1] in keep and keep else ""
        return ticker.FuncFormatter(label)

    for axis in (ax.xaxis, ax.yaxis):
        if axis.get_scale() != "log":
            continue
        axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(minor(axis))


def noise_line(ax, noise_percent, **style):
    """The reference's own noise as a horizontal line, its value written on it."""
    ax.axhline(noise_percent, color="grey", linestyle=style.pop("linestyle", ":"),
               label=f"noise of the path-traced reference ({noise_percent:.2g}%)", **style)
    ax.annotate(f"reference noise {noise_percent:.2g}%", xy=(0.01, noise_percent), xycoords=("axes fraction", "data"),
                xytext=(0, 2), textcoords="offset points", fontsize=7, color="dimgrey", va="bottom")


def wrapped(text, width=90):
    """A title broken into lines of at most `width` characters (a long one is clipped otherwise)."""
    return "\n".join(textwrap.fill(line, width) for line in text.split("\n"))


def save(fig, path, dpi=100):
    """Written whole (titles and a legend outside the axes included), through a temporary file."""
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
    os.replace(tmp, path)
