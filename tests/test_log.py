"""The textile logger (textile.log): the rank in its lines, ranks > 0
quiet, INFO to stdout and warnings to stderr."""
import pytest

from textile import log


@pytest.fixture
def restore():
    yield
    log.configure()          # as textile's import left it


def say(capsys):
    logger = log.get_logger("textile.somewhere")
    logger.info("step 1")
    logger.warning("careful")
    return capsys.readouterr()


def test_one_rank_prints_bare_messages(capsys, restore, monkeypatch):
    monkeypatch.setattr(log, "_world_rank_size", lambda: (0, 1))
    log.configure()
    out, err = say(capsys)
    assert (out, err) == ("step 1\n", "careful\n")


def test_ranks_are_named_and_ranks_beyond_0_quiet(capsys, restore, monkeypatch):
    monkeypatch.setattr(log, "_world_rank_size", lambda: (0, 2))
    log.configure()
    assert say(capsys) == ("[rank 0] step 1\n", "[rank 0] careful\n")
    monkeypatch.setattr(log, "_world_rank_size", lambda: (1, 2))
    log.configure()
    assert say(capsys) == ("", "[rank 1] careful\n")        # warnings only
    log.configure(all_ranks=True)
    assert say(capsys) == ("[rank 1] step 1\n", "[rank 1] careful\n")
    log.configure("warning")
    assert say(capsys) == ("", "[rank 1] careful\n")


def test_configured_once_not_twice(capsys, restore):
    log.configure()
    log.configure()
    log.get_logger(__name__).info("once")     # a module outside textile: under textile.
    assert capsys.readouterr().out.count("once") == 1
