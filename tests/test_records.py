"""What every record says of the code that made it (issue 46, item 4)."""

from __future__ import annotations


def test_every_record_says_the_working_directory_and_whether_the_tree_was_dirty(monkeypatch, tmp_path):
    """Issue 46, item 4: two records that name the same commit ran the same code only if neither
    tree had uncommitted changes, or both had the same diff (its digest is recorded)."""
    import hashlib

    from rover_cosim.common import outputs

    answers = {("rev-parse", "HEAD"): b"abc123\n", ("status", "--porcelain", "--untracked-files=no"): b" M x.py\n",
               ("diff", "HEAD"): b"the diff"}
    monkeypatch.setattr(outputs, "_git", lambda *arguments: answers.get(arguments))
    outputs.source_tree.cache_clear()
    monkeypatch.chdir(tmp_path)
    try:
        record = outputs.run_record("rover-cosim fig3", {})
    finally:
        outputs.source_tree.cache_clear()
    assert record["working_directory"] == str(tmp_path)
    assert record["git_commit"] == "abc123" and record["git_dirty"] is True
    assert record["git_diff_sha256"] == hashlib.sha256(b"the diff").hexdigest()
    answers[("status", "--porcelain", "--untracked-files=no")] = b""
    record = outputs.run_record("rover-cosim fig3", {})
    outputs.source_tree.cache_clear()
    assert record["git_dirty"] is False and "git_diff_sha256" not in record
