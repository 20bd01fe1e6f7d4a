"""A damaged store (a part truncated as a full disk or a crashed file system would leave it) is detected on
every read, refused by every command that reads it, listed by `store verify`, and repaired by `store
repair` so that the next sweep reruns exactly the lost runs."""
import os
import stat

import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.store import Store, StoreDamaged

SWEEP = ["--workers", "1", "--quiet"]
VOLATILE = ["duration_s", "robots_sha256", "history_sha256", "events_sha256",
            "robots_rows", "history_rows", "events_rows"]


def truncate(path, keep=0.5):
    data = path.read_bytes()
    path.write_bytes(data[: int(len(data) * keep)])


def sweep(exp, out, *extra):
    return main(["sweep", str(exp), "--out", str(out), *SWEEP, *extra])


@pytest.fixture
def store(tiny, tmp_path):
    out = tmp_path / "s"
    assert sweep(tiny(), out) == 0
    return Store(out)


def first_part(store, table):
    return sorted((store.root / table).glob("part-*.parquet"))[0]


def test_commit_records_hold_each_parts_checksum_and_rows(store):
    import hashlib

    runs = store.runs()
    assert len(runs) == 6 and (runs.status == "ok").all()
    part = store.root / "robots" / f"part-{store.committed()[0]}.parquet"
    rec = pd.read_parquet(store.root / "runs" / part.name)
    assert rec.robots_sha256.iloc[0] == hashlib.sha256(part.read_bytes()).hexdigest()
    assert rec.robots_rows.iloc[0] == 6 * len(rec)  # six robots per run


def test_truncated_robots_part_is_refused_by_every_reader(store, tiny, tmp_path, capsys):
    part = first_part(store, "robots")
    truncate(part)
    with pytest.raises(StoreDamaged, match=f"robots/{part.name}"):
        store.robots()
    capsys.readouterr()
    assert main(["figures", str(store.root), "--out", str(tmp_path / "fig")]) == 2
    err = capsys.readouterr().err
    assert f"robots/{part.name} is damaged" in err and f"infomarket store repair {store.root}" in err
    assert "Traceback" not in err and not (tmp_path / "fig").exists()
    assert sweep(tiny(), store.root) == 2
    assert "infomarket store repair" in capsys.readouterr().err
    assert main(["store", "verify", str(store.root)]) == 2
    out = capsys.readouterr().out
    assert f"damaged: robots/{part.name}: checksum mismatch" in out


def test_truncated_commit_record_is_refused_not_a_crash(store, tiny, capsys):
    part = first_part(store, "runs")
    truncate(part)
    assert sweep(tiny(), store.root) == 2
    err = capsys.readouterr().err
    assert f"runs/{part.name} is damaged" in err and "Traceback" not in err


def test_verify_repair_sweep_ends_like_an_undamaged_store(store, tiny, tmp_path, capsys):
    reference = {t: getattr(store, t)() for t in ("robots", "runs")}
    robots_part, runs_part = first_part(store, "robots"), sorted((store.root / "runs").glob("*.parquet"))[-1]
    truncate(robots_part)
    truncate(runs_part, 0.9)
    orphan = store.root / "robots" / "part-orphan.parquet"
    orphan.write_bytes(b"left by a crash")
    assert main(["store", "verify", str(store.root)]) == 2
    out = capsys.readouterr().out
    assert out.count("damaged:") == 2 and "orphan:  robots/part-orphan.parquet" in out
    damaged_bytes = robots_part.read_bytes()
    assert main(["store", "repair", str(store.root)]) == 0
    moved = list((store.root / "damaged").rglob("*.parquet"))
    assert damaged_bytes in [m.read_bytes() for m in moved]  # moved aside, never deleted
    assert main(["store", "verify", str(store.root)]) == 0
    assert len(store.runs()) < 6  # the damaged parts' runs are no longer committed
    assert sweep(tiny(), store.root) == 0
    for t, ref in reference.items():
        now = getattr(store, t)()
        pd.testing.assert_frame_equal(now.drop(columns=[c for c in VOLATILE if c in now]),
                                      ref.drop(columns=[c for c in VOLATILE if c in ref]), check_exact=True)


def test_parts_get_the_umasks_permissions(tiny, tmp_path):
    old = os.umask(0o022)
    try:
        out = tmp_path / "s"
        assert sweep(tiny(), out) == 0
        assert main(["run", str(tiny()), "--runs", "1", "--out", str(tmp_path / "r"), "--quiet"]) == 0
    finally:
        os.umask(old)
    run = tmp_path / "r"  # `infomarket run` writes a store too
    files = list(out.rglob("*.parquet")) + [out / "store.json"] + list(run.rglob("*.parquet")) + [run / "store.json"]
    assert any(f.parent == run / "robots" for f in files)
    assert files and {stat.S_IMODE(f.stat().st_mode) for f in files} == {0o644}


@pytest.mark.parametrize("keep_metadata", [True, False], ids=["metadata-kept", "rewritten-by-pandas"])
def test_one_value_edited_in_a_commit_record_fails_verify(store, tmp_path, capsys, keep_metadata):
    # issue 21: a runs part rewritten as valid Parquet with one value changed passed verify and figures
    import pyarrow as pa
    import pyarrow.parquet as pq

    part = first_part(store, "runs")
    table = pq.read_table(part)
    seeds = table.column("seed").to_pylist()
    seeds[0] += 1
    edited = table.set_column(table.column_names.index("seed"), "seed",
                              pa.array(seeds, table.schema.field("seed").type))
    if keep_metadata:
        pq.write_table(edited, part)
    else:
        edited.to_pandas().to_parquet(part, index=False)
    assert main(["store", "verify", str(store.root)]) == 2
    out = capsys.readouterr().out
    assert f"damaged: runs/{part.name}: commit record" in out
    with pytest.raises(StoreDamaged, match=f"runs/{part.name} is damaged: commit record"):
        store.runs()
    assert main(["figures", str(store.root), "--out", str(tmp_path / "fig")]) == 2
    assert not (tmp_path / "fig").exists()


def test_an_untouched_store_verifies(store, capsys):
    assert main(["store", "verify", str(store.root)]) == 0
    assert len(store.runs()) == 6


def test_a_caching_store_reads_each_part_once_and_still_sees_damage(store, tiny, monkeypatch):
    """``Store(root, cache=True)`` (the attack search's store, read after every generation) reads and
    verifies each part once; a part changed on disk afterwards is read again and refused."""
    import infomarket.store.integrity as integrity
    import infomarket.store.results as results

    def on_disk():  # (commit records, data parts): what one full check and read must open, counted by glob
        records = len(list((store.root / "runs").glob("part-*.parquet")))
        data = sum(len(list((store.root / t).glob("part-*.parquet"))) for t in results.DATA_TABLES)
        return records, data

    cached = Store(store.root, cache=True)
    calls = {"files": 0, "sha256": 0}  # files read (commit records and robots parts), data parts hashed
    read_table, sha = results.pq.read_table, integrity.sha256_file

    def counting_read(*a, **kw):
        calls["files"] += counting
        return read_table(*a, **kw)

    def counting_sha(path):
        calls["sha256"] += counting
        return sha(path)

    monkeypatch.setattr(results.pq, "read_table", counting_read)
    monkeypatch.setattr(integrity, "sha256_file", counting_sha)

    def read_all():
        cached.check()
        done = cached.completed_runs()
        return cached.robots(), done

    counting = True  # off while the sweep below writes
    records, data = on_disk()
    first, done = read_all()
    assert calls == {"files": 2 * records, "sha256": data}
    again, done_again = read_all()
    pd.testing.assert_frame_equal(again, first)
    assert done_again == done
    assert calls == {"files": 2 * records, "sha256": data}, "a second read went back to the files"
    # a sweep adds parts: only they are read
    counting = False
    assert sweep(tiny(runs=5), store.root) == 0
    counting = True
    records2, data2 = on_disk()
    more, more_done = read_all()
    assert records2 > records and len(more) > len(first) and more_done > done
    assert calls == {"files": 2 * records2, "sha256": data2}
    truncate(first_part(store, "robots"))
    with pytest.raises(StoreDamaged, match="checksum mismatch"):
        cached.robots()
