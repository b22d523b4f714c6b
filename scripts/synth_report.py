"""What scripts/synth's readers and tables share: nextpnr's critical path in RTL names, and how a
row's label reads in the table."""
import re


def stem(cell):
    """The RTL name behind a mapped cell: cut the techmap suffix (_TRELLIS_FF_Q_3, _CCU2C_.., $..)."""
    if cell.startswith("$gbuf"):
        # nextpnr-ice40's global buffer for a high-fanout net (`$gbuf_<net>_$glb_ce`).
        return "(global buffer)"
    if cell.startswith("$nextpnr_"):
        # A logic cell nextpnr's packer added (on iCE40: to bring a signal into a carry chain).
        return "(packer's cell)"
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


def path_text(cp, missing="-"):
    """A critical path as the tables print it."""
    if not cp:
        return missing
    return f'{" → ".join(cp["through"])} ({cp["ns"]:.1f} ns: {cp["logic_ns"]:.1f} logic, {cp["routing_ns"]:.1f} routing)'


def level(tag):
    """'+pl2' in a label: the --pipeline level, as the form column says it."""
    return f"--pipeline {tag[3:]}" if tag else ""


def tag_option(t):
    """One '+'-separated tag of a front-end or chain label as the option it stands for:
    'pl1' --pipeline 1, 'div2' --fe-div-bits 2, 'span-sequential' --fe-span sequential,
    'spec2' the specular unit's --pipeline 2, any other the --fe-setup plan."""
    if t.startswith("pl"):
        return level("+" + t)
    if t.startswith("div"):
        return f"--fe-div-bits {t[3:]}"
    if t.startswith("span-"):
        return f"--fe-span {t[5:]}"
    if t.startswith("spec") and t[4:].isdigit():
        return f"specular --pipeline {t[4:]}"
    return f"--fe-setup {t}"


def block_form(r):
    """The block and form columns of a row: 'shift-add+pl2/p8' reads P = 8, shift-add, --pipeline 2."""
    if r["label"].startswith("frontend"):
        # 'frontend+pl1+div2': --pipeline 1 --fe-div-bits 2; '+ecp5-25f': --fe-setup ecp5-25f
        tags = r["label"].split("+")[1:]
        return r["top"], ", ".join(map(tag_option, tags)) or "—"
    if r["label"].startswith("chain-"):
        # 'chain-screen+pl1+ecp5-25f/p16': tri_fb_p16 (and specular_unit), screen alignment,
        # --pipeline 1, --fe-setup ecp5-25f
        form, _, _ = r["label"].partition("/")
        align, *tags = form[len("chain-"):].split("+")
        parts = [f"--align {align}"] + [tag_option(t) for t in tags]
        return " + ".join(r["top"].split("+")), ", ".join(parts)
    if r["label"].startswith("specular"):
        return r["top"], level(r["label"][len("specular"):]) or "—"
    if r["label"].startswith("ref/"):
        ref = r["label"][4:]
        if ref.startswith("acc"):
            return f"reference: {ref[3:]}-bit accumulator", "—"
        return f"reference: {ref[3:].replace('x', ' × ')} multiplier", "—"
    form, p = r["label"].split("/")
    form, _, pl = form.partition("+")
    return f"P = {p[1:]}", ", ".join(filter(None, [form, level("+" + pl if pl else "")]))
