"""What every bounce chart shares (imported by the plot_*.py scripts beside it)."""
import matplotlib.ticker as ticker


def plain_ticks(ax):
    """Decimal tick labels (0.5, 2, 30) instead of powers of ten on short log ranges."""
    import math

    def minor(axis):
        # Minor labels (2, 3, 5) only where the axis spans too few decades for the majors to read;
        # decided when drawn, once the limits are final.
        def label(v, _):
            lo, hi = axis.get_view_interval()
            few = lo > 0 and math.log10(hi / lo) < 1.5
            return f"{v:g}" if few and f"{v:g}"[0] in "235" else ""
        return ticker.FuncFormatter(label)

    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(minor(axis))
