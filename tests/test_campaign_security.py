"""`--scheduler tcp://...` trusts the scheduler completely (Dask unpickles the results): plain tcp:// beyond this
machine is refused unless --insecure, TLS credentials come from --scheduler-security FILE or Dask's configuration,
and the help says why (issue 18, Campaigns: security)."""

import json

import pytest

from fowt_env import campaign as K
from fowt_env.cli import build_parser, main


@pytest.mark.parametrize("spec", ["tcp://10.0.0.5:8786", "tcp://scheduler-host:8786", "tcp://[2001:db8::1]:8786",
                                  "ucx://10.0.0.5:8786"])
def test_plain_tcp_beyond_loopback_is_refused_without_insecure(spec):
    with pytest.raises(ValueError, match="unpickles them.*--insecure"), K.parse_scheduler(spec):
        pass  # pragma: no cover - refused before any connection


@pytest.mark.parametrize(("spec", "insecure"), [("tcp://127.0.0.1:8786", False), ("tcp://localhost:8786", False),
                                                ("tcp://[::1]:8786", False), ("tcp://10.0.0.5:8786", True),
                                                ("tls://10.0.0.5:8786", False)])
def test_loopback_tls_or_insecure_go_on_to_connect(monkeypatch, spec, insecure):
    import distributed

    tried = []

    def no_network(address, **kwargs):
        tried.append((address, kwargs))
        raise OSError("no network in this test")

    monkeypatch.setattr(distributed, "Client", no_network)
    with pytest.raises(ValueError, match="cannot connect to a Dask scheduler"), \
            K.parse_scheduler(spec, insecure=insecure):
        pass  # pragma: no cover
    assert [a for a, _ in tried] == [spec]


def test_a_security_file_in_dasks_layout_or_as_keywords(tmp_path, monkeypatch):
    import distributed

    for name in ("ca.pem", "client.pem", "client-key.pem"):
        (tmp_path / name).write_text("-")
    dask_layout = tmp_path / "security.yaml"
    dask_layout.write_text("distributed:\n  comm:\n    require-encryption: true\n    tls:\n      ca-file: ca.pem\n"
                           "      client:\n        cert: client.pem\n        key: client-key.pem\n")
    keywords = tmp_path / "security.json"
    keywords.write_text(json.dumps({"tls_ca_file": "ca.pem", "tls_client_cert": "client.pem",
                                    "tls_client_key": "client-key.pem", "require_encryption": True}))
    for path in (dask_layout, keywords):
        sec = K.load_security(path)
        assert sec.require_encryption and sec.tls_ca_file == str(tmp_path / "ca.pem")
        assert sec.tls_client_key == str(tmp_path / "client-key.pem")
    seen = []

    def no_network(address, **kwargs):
        seen.append(kwargs.get("security"))
        raise OSError("no network in this test")

    monkeypatch.setattr(distributed, "Client", no_network)
    with pytest.raises(ValueError, match="cannot connect"), K.parse_scheduler("tls://10.0.0.5:8786",
                                                                               security=str(dask_layout)):
        pass  # pragma: no cover
    assert isinstance(seen[0], distributed.Security) and seen[0].tls_client_cert == str(tmp_path / "client.pem")

    (tmp_path / "missing.yaml").write_text("tls_ca_file: nowhere.pem\n")
    for bad, needle in [(tmp_path / "none.yaml", "cannot read"), (tmp_path / "missing.yaml", "does not exist")]:
        with pytest.raises(ValueError, match=needle):
            K.load_security(bad)


def test_the_help_says_whom_the_scheduler_must_be_trusted_by(tmp_path, capsys):
    for command in ("compare", "campaign"):
        text = " ".join(build_parser().subcommands[command].format_help().split())
        assert "unpickles" in text and "--insecure" in text and "--scheduler-security" in text
    assert main(["campaign", "--out", str(tmp_path / "camp"), "--scheduler", "tcp://10.0.0.5:8786"]) == 2
    err = capsys.readouterr().err
    assert "refused" in err and "--insecure" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "camp").exists()


@pytest.mark.slow
def test_a_tls_scheduler_with_a_security_file_runs_tasks(tmp_path):
    """A real TLS round trip: an in-process Dask cluster with temporary certificates, the client's credentials
    read from a --scheduler-security file."""
    import distributed

    pytest.importorskip("cryptography", reason="distributed.Security.temporary() needs cryptography (test extras)")
    sec = distributed.Security.temporary()
    creds = tmp_path / "security.json"
    creds.write_text(json.dumps({"tls_ca_file": sec.tls_ca_file, "tls_client_cert": sec.tls_client_cert,
                                 "tls_client_key": sec.tls_client_key, "require_encryption": True}))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, security=sec,
                                  host="127.0.0.1", scheduler_port=0, dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tls://")
        with K.parse_scheduler(cluster.scheduler_address, security=creds) as ex:
            assert ex.submit(sum, [1, 2, 3]).result(timeout=60) == 6
        with pytest.raises(ValueError, match="cannot connect"), \
                K.parse_scheduler(cluster.scheduler_address.replace("tls://", "tcp://"), timeout="2s"):
            pass  # pragma: no cover - plain tcp to a TLS scheduler
