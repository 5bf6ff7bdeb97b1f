"""``benchmarks/_report.section_rows``: the rows a partial rerun of a benchmark would drop from its docs section
(``scaling.py --scenes`` keeps the section then, unless ``--write-docs``)."""
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
