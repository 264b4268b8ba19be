"""Find the newest waves: VCD (or FST) files and the GTKWave save file beside each."""

from .paths import BUILD

__all__ = ["latest", "main"]


def latest(n=5):
    files = [p for ext in ("*.vcd", "*.fst") for p in BUILD.rglob(ext)] if BUILD.exists() else []
    files.sort(key=lambda p: p.stat().st_mtime, reverse=True)
    return [(p, p.with_suffix(".gtkw") if p.with_suffix(".gtkw").exists() else None) for p in files[:n]]


def main():
    found = latest()
    if not found:
        print("no waves yet: run `make sim` or `make test` (WAVES=1 for the cocotb runs)")
        return 1
    print("newest waves (open with: gtkwave <save file>, or gtkwave <vcd>):")
    for vcd, gtkw in found:
        print(f"  {vcd}" + (f"\n    save file: {gtkw}" if gtkw else ""))
    return 0
