"""The stamp of the kernel sources (kernel_cache.py): cached kernels compiled from other sources are deleted before
a run can load them; unchanged sources keep the cache."""

from __future__ import annotations

from covcontact import kernel_cache


def test_stale_kernels_are_cleared(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    folder = tmp_path / "covcontact_elements"  # (numba names its folders after the sources' paths)
    folder.mkdir()
    other = tmp_path / "another_package"
    other.mkdir()
    (other / "f.nbi").write_text("x")
    (folder / "solid._element-1.py311.nbi").write_text("x")
    (folder / "solid._element-1.py311.1.nbc").write_text("x")
    assert kernel_cache.check()  # no stamp yet: cleared
    assert not list(folder.glob("*.nb?")) and (other / "f.nbi").exists()
    assert (tmp_path / kernel_cache.STAMP).read_text().strip() == kernel_cache.digest(kernel_cache.kernel_sources())
    (folder / "solid._element-1.py311.nbi").write_text("x")
    assert not kernel_cache.check()  # the same sources: the cache stays
    assert (folder / "solid._element-1.py311.nbi").exists()
    monkeypatch.setattr(kernel_cache, "digest", lambda paths: "an edited material law")
    assert kernel_cache.check()  # a kernel module changed: cleared
    assert not (folder / "solid._element-1.py311.nbi").exists()


def test_the_stamp_covers_the_material_and_element_kernels():
    names = {p.name for p in kernel_cache.kernel_sources()}
    assert {"hyperelastic.py", "solid.py", "update.py", "kernels.py"} <= names
    # modules that only name numba or use its thread count: editing them keeps the compiled kernels
    assert not {"warmup.py", "cli.py", "compile_notice.py", "kernel_cache.py"} & names
