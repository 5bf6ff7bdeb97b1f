"""``benchmarks/_report.section_rows``: the rows a partial rerun of a benchmark would drop from its docs section
(``scaling.py --scenes`` and ``--step-parts`` keep the section then, unless ``--write-docs``)."""
import _report

DOC = """# Benchmarks

<!-- BEGIN demo -->
## A section

| scene | time |
|---|---:|
| 19 | 0.2 |
| rope-40 | 0.5 |

(a note | with a bar)
<!-- END demo -->
"""


def test_section_rows_are_the_first_cells_of_the_table(tmp_path):
    doc = tmp_path / "benchmarks.md"
    doc.write_text(DOC)
    assert _report.section_rows("demo", doc) == ["19", "rope-40"]
    assert _report.section_rows("absent", doc) == []


def test_a_rewritten_section_has_only_the_new_rows(tmp_path):
    doc = tmp_path / "benchmarks.md"
    doc.write_text(DOC)
    _report.write_section("demo", "| scene | time |\n|---|---:|\n| 37 | 0.7 |\n", doc)
    assert _report.section_rows("demo", doc) == ["37"]


STEP_PARTS = """<!-- BEGIN parts -->
| scene | threads | iteration | total |
|---|---|---|---|
| strand-37 | 1 | first | 0.42 |
| strand-37 | 1 | later | 0.38 |
| strand-61 | 1 | first | 0.63 |
| strand-61 | 1 | later | 0.61 |
| 19 | 1 | first | 0.31 |
<!-- END parts -->
"""


def test_a_partial_rerun_names_each_scene_it_would_drop_once(tmp_path):
    import scaling
    doc = tmp_path / "benchmarks.md"
    doc.write_text(STEP_PARTS)
    assert scaling._dropped_rows(["strand-37"], "parts", doc) == ["strand-61", "19"]
    assert scaling._dropped_rows(["19", "strand-61", "strand-37"], "parts", doc) == []
    assert scaling._dropped_rows(["strand-37"], "absent", doc) == []


def test_the_main_job_profile_sorts_work_by_kind():
    import main_job_profile as mp
    compiled = {("/x/beamsolver/contact/kernel_jit.py", 10, "_evaluate_mortar")}
    assert mp.kind(("/x/beamsolver/contact/kernel_jit.py", 10, "_evaluate_mortar"), compiled) == "compiled kernels"
    assert mp.kind(("/x/beamsolver/contact/system.py", 5, "_mortar"), compiled) == "Python glue"
    assert mp.kind(("/x/beamsolver/nonlinear/linsolve.py", 391, "__init__"), compiled) == "linear solver"
    assert mp.kind(("~", 0, "<built-in method scipy.sparse.linalg._dsolve._superlu.gstrf>"), compiled) == \
        "linear solver"
    assert mp.kind(("~", 0, "<method 'reduce' of 'numpy.ufunc' objects>"), compiled) == "numpy / scipy calls"
    assert mp.kind(("/v/site-packages/numpy/linalg/_linalg.py", 2599, "norm"), compiled) == "numpy / scipy calls"
    assert mp.kind(("~", 0, "<built-in method builtins.len>"), compiled) == "Python glue"
    assert mp.kind(("/usr/lib/python3.11/logging/__init__.py", 1, "debug"), compiled) == "other"
