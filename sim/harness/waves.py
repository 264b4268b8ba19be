"""Find the newest waves: VCD (or FST) files and the GTKWave save file beside each."""

from .paths import BUILD

__all__ = ["latest", "declared", "main"]


def latest(n=5):
    files = [p for ext in ("*.vcd", "*.fst") for p in BUILD.rglob(ext)] if BUILD.exists() else []
    files.sort(key=lambda p: p.stat().st_mtime, reverse=True)
    return [(p, p.with_suffix(".gtkw") if p.with_suffix(".gtkw").exists() else None) for p in files[:n]]


def declared(vcd):
    """The variables ``vcd`` declares, as GTKWave names them: ``{scope path: [name or
    name[msb:lsb], ..]}`` (the header only is read)."""
    scopes, path = {}, []
    with open(vcd) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "$scope":
                path.append(words[2])
                scopes.setdefault(".".join(path), [])
            elif words[0] == "$upscope":
                path.pop()
            elif words[0] == "$var":
                # $var <type> <width> <id> <name> [<range>] $end
                scopes[".".join(path)].append("".join(words[4:-1]))
            elif words[0] == "$enddefinitions":
                break
    return scopes


def main():
    found = latest()
    if not found:
        print("no waves yet: run `make sim` or `make test` (WAVES=1 for the cocotb runs)")
        return 1
    print("newest waves (open with: gtkwave <save file>, or gtkwave <vcd>):")
    for vcd, gtkw in found:
        print(f"  {vcd}" + (f"\n    save file: {gtkw}" if gtkw else ""))
    return 0
