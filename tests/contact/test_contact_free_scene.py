"""A scene without contact runs none of the contact code, and no solve loads a test oracle
(``contact.reference``, ``elements.reference``) (fresh interpreter, clean sys.modules)."""
import pytest
import json
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import json, sys
    import numpy as np
    import beamsolver as bs
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=1e9))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, -1.0))
    sol = bs.solve(m, steps=2)
    out = dict(system="beamsolver.contact.system" in sys.modules,
               search="beamsolver.contact.search" in sys.modules,
               pairs="beamsolver.contact.pairs" in sys.modules,
               oracle="beamsolver.elements.reference" in sys.modules,
               contact=[len(c) for c in sol.contacts])
    print(json.dumps(out))
""")

SCRIPT_CONTACT = textwrap.dedent("""
    import json, sys
    from collections import Counter
    import beamsolver as bs
    from beamsolver.contact import system as cs
    calls = Counter()

    def counted(name, f):
        def g(*a, **k):
            calls[name] += 1
            return f(*a, **k)
        return g
    cs.ContactSystem.pairs = counted("search", cs.ContactSystem.pairs)
    cs.ContactSystem.evaluate = counted("evaluate", cs.ContactSystem.evaluate)
    sec = bs.Section.circular(radius=0.05, E=1e7)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 3), sec)
    b = m.add_beam(bs.geometry.straight((-1, 0, 1), (1, 0, 1), 3), sec)
    for n in (a.first, a.last, b.first, b.last):
        m.clamp(n)
    m.add_contact(b, a, mu=0.2)
    bs.solve(m, steps=1)
    calls["oracles"] = sum(k in sys.modules for k in ("beamsolver.contact.reference", "beamsolver.elements.reference"))
    print(json.dumps(dict(calls)))
""")


def _run(script):
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_scene_without_contact_never_imports_the_contact_system():
    out = _run(SCRIPT)
    assert out == dict(system=False, search=False, pairs=False, oracle=False, contact=[0, 0, 0])


@pytest.mark.slow
def test_contact_code_runs_when_there_is_contact():
    calls = _run(SCRIPT_CONTACT)          # the sys.modules probe above would see this code if it ran
    assert calls.get("search", 0) > 0 and calls.get("evaluate", 0) > 0
    assert calls["oracles"] == 0                 # a frictional contact solve runs without the oracles
