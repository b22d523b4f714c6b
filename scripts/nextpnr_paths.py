"""The clock-to-clock critical path of a nextpnr --report JSON, in RTL names (scripts/synth)."""
import re


def stem(cell):
    """The RTL name behind a mapped cell: cut the techmap suffix (_TRELLIS_FF_Q_3, _CCU2C_.., $..)."""
    s = re.split(r"\$|_(?=[A-Z])", cell)[0]
    s = re.sub(r"(\.\d+)+$", "", s)
    s = {"in_q": "(input regs)", "out_q": "(output regs)"}.get(s, s)
    return s[len("u_block."):] if s.startswith("u_block.") else s

def critical(rep):
    """The clock-to-clock critical path: the RTL names it runs through, and its delay split."""
    for cp in rep.get("critical_paths", []):
        if cp["from"].startswith("posedge") and cp["to"].startswith("posedge") and cp["path"]:
            names = []
            for el in cp["path"]:
                for end in ("from", "to"):
                    n = stem(el[end]["cell"])
                    if not names or names[-1] != n:
                        names.append(n)
            route = sum(el["delay"] for el in cp["path"] if el["type"] == "routing")
            total = sum(el["delay"] for el in cp["path"])
            if len(names) > 7:
                names = names[:3] + ["…"] + names[-3:]
            return {"through": names, "ns": round(total, 2), "logic_ns": round(total - route, 2),
                    "routing_ns": round(route, 2)}
    return None
