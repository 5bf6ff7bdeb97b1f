"""Progress of a solve over pseudo-time: tqdm bar, per-step lines, log records."""
import logging
import sys

__all__ = ["Progress"]

log = logging.getLogger("beamsolver")


class Progress:
    """Progress over pseudo-time: a tqdm bar on a terminal, per-step lines otherwise.

    ``verbose``: ``None`` (default) a bar when stderr is a terminal, else
    silent; ``True`` a bar on a terminal, else one printed line per step;
    ``False`` silent.  Details always go to ``logging.getLogger("beamsolver")``.
    """

    def __init__(self, verbose, t0, t1, t):
        tty = sys.stderr.isatty()
        self.lines = verbose is True and not tty
        self.bar = None
        if verbose is not False and tty:
            from tqdm import tqdm
            # tqdm puts ", " before a postfix: the text after "t = " lives in ``unit`` instead
            self.bar = tqdm(total=t1 - t0, initial=t - t0, desc="beamsolver", leave=True, dynamic_ncols=True,
                            unit=f"{t:.4g}",
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| t = {unit} [{elapsed}<{remaining}]")

    def step(self, k, t, dt, stats):
        it, res, cut = stats["iterations"], stats["residuals"][-1], stats["cutbacks"]
        log.info("step %d  t = %.6g  iterations %d  residual %.2e  cut-backs %d  wall %.3f s",
                 k, t, it, res, cut, stats["wall_time"])
        if self.bar is not None:
            self.bar.unit = f"{t:.4g}  step {k}  iterations {it}  residual {res:.1e}"
            self.bar.update(dt)
        elif self.lines:
            print(f"t = {t:.6g}  iterations {it}  residual {res:.2e}  cut-backs {cut}")

    def close(self):
        if self.bar is not None:
            self.bar.close()
            self.bar = None
