"""Fuzzing the .zmx, .seq and OSLO .len readers: a deterministic mutation corpus of damaged
files (truncated, reordered or duplicated lines, garbage numbers and tokens, wrong encodings,
bit flips, random binary) plus a hypothesis test on random command soup. Every reader call must
either return a valid Lens or raise PrescriptionError carrying the path and a line number —
never another exception, never a hang (each call is bounded by a timer)."""

from __future__ import annotations

import codecs
import random
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import time_limit

from raytrace.errors import PrescriptionError
from raytrace.files.codev import parse_seq
from raytrace.files.library import load_lens
from raytrace.files.oslo import parse_len
from raytrace.files.zemax import dumps_zmx, parse_zmx
from raytrace.glass import catalog_available, find_glass
from raytrace.lens import Lens

DATA = Path(__file__).parent / "data"
N_MUTANTS = 1200
PER_FILE_LIMIT_S = 2.0

GARBAGE = [
    "nan",
    "inf",
    "-inf",
    "1e999",
    "-1e999",
    "",
    "abc",
    "0",
    "-0",
    "1e-320",
    "9" * 60,
    "1,5",
    "0x10",
    "1e308",
    "-5",
    "INFINITY",
    "\u221e",
    "1_0",
    "''",
    '"',
    "&",
    ";",
    "!",
    "\u00e9\u00e8",
    "-1",
    "1e10",
    "4.0.0",
    "+",
    "1e-5",
    "100000000",
    "STO",
    "SURF",
]
VOCAB_ZMX = (
    "SURF TYPE CURV DISZ DIAM CONI PARM GLAS STOP COMM CLAP XDAT ENPD FNUM OBNA FTYP XFLN YFLN "
    "WAVM WAVL PWAV UNIT MODE NAME NOTE GCAT MNUM CONF FLOA DECX SCBD"
).split()
VOCAB_SEQ = (
    "SO S SI STO RDM DIM EPD FNO NAO WL REF YAN XAN YOB XOB YIM ASP K A B C D E PIM CIR SLB "
    "TIT LEN GO PRV END ADE REFL PIK CCY THC"
).split()


def _check(reader, data: bytes, path: str) -> str:
    """Run one reader; return "ok" or "error", failing the test on anything else."""
    try:
        with time_limit(PER_FILE_LIMIT_S):
            res = reader(data, path=path)
    except PrescriptionError as e:
        assert e.line is not None, f"no line number: {e}"
        assert e.path == path
        return "error"
    assert isinstance(res.lens, Lens)
    return "ok"


def _seeds() -> list[tuple[str, bytes]]:
    out = [
        ("zmx", (DATA / "cooke-triplet-f4.zmx").read_bytes()),
        ("zmx", (DATA / "topogon-us2031792-fig1.zmx").read_bytes()),
        ("seq", (DATA / "cooke-triplet-f4.seq").read_bytes()),
        ("seq", (DATA / "topogon-us2031792-fig1.seq").read_bytes()),
    ]
    for name in ("super-angulon-de975637", "tessar-fr1066698"):
        out.append(("zmx", dumps_zmx(load_lens(name)).encode()))
    # real OSLO files (tests/data/corpus/SOURCES.md: optiland 0.6.3's OSLO test files)
    for name in ("test_cooke_triplet.len", "cox3_07.len"):
        out.append(("len", (DATA / "corpus" / "optiland" / name).read_bytes()))
    return out


READERS = {"zmx": parse_zmx, "seq": parse_seq, "len": parse_len}
OTHER = {"zmx": parse_seq, "seq": parse_zmx, "len": parse_zmx}


def _text(data: bytes) -> str:
    if data[:2] == codecs.BOM_UTF16_LE:
        return data[2:].decode("utf-16-le", errors="replace")
    return data.decode("utf-8", errors="replace")


def _mutate(rng: random.Random, data: bytes) -> bytes:
    op = rng.randrange(12)
    if op == 0:  # truncated
        return data[: rng.randrange(len(data) + 1)]
    if op == 1:  # random binary
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400)))
    if op == 2:  # bit flips
        b = bytearray(data)
        for _ in range(rng.randrange(1, 20)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
        return bytes(b)
    if op == 3:  # random bytes inserted
        i = rng.randrange(len(data) + 1)
        return data[:i] + bytes(rng.randrange(256) for _ in range(rng.randrange(1, 30))) + data[i:]
    text = _text(data)
    lines = text.split("\n")
    if op == 4:  # lines deleted
        for _ in range(rng.randrange(1, 6)):
            if lines:
                del lines[rng.randrange(len(lines))]
    elif op == 5:  # lines swapped / block shuffled
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
        if rng.random() < 0.3:
            k = rng.randrange(len(lines))
            block = lines[k : k + 8]
            rng.shuffle(block)
            lines[k : k + 8] = block
    elif op == 6:  # line duplicated
        i = rng.randrange(len(lines))
        lines.insert(rng.randrange(len(lines)), lines[i])
    elif op in (7, 8):  # garbage tokens (numbers mostly)
        for _ in range(rng.randrange(1, 5)):
            i = rng.randrange(len(lines))
            toks = lines[i].split()
            if toks:
                j = rng.randrange(1, len(toks)) if len(toks) > 1 and op == 7 else 0
                toks[j] = rng.choice(GARBAGE)
                lines[i] = " ".join(toks)
    elif op == 9:  # random command inserted
        cmd = rng.choice(VOCAB_ZMX + VOCAB_SEQ)
        args = " ".join(rng.choice(GARBAGE + ["1", "2", "0.5", "N-BK7"]) for _ in range(3))
        lines.insert(rng.randrange(len(lines) + 1), f"{cmd} {args}")
    text = "\n".join(lines)
    if op == 10:  # wrong or unusual encodings
        enc = rng.choice(["utf-16-le", "utf-16-be", "utf-32", "cp1252", "utf-16", "latin-1"])
        return text.encode(enc, errors="replace")
    if op == 11:  # half UTF-16, half ASCII
        half = len(text) // 2
        return text[:half].encode("utf-16-le") + text[half:].encode("ascii", errors="replace")
    return text.encode("utf-8", errors="replace")


@pytest.fixture(scope="module", autouse=True)
def _catalogs_loaded():
    """Load the glass catalogs once, outside the per-file time limit."""
    if catalog_available():
        find_glass("N-BK7")


def test_mutation_corpus_only_prescription_errors():
    rng = random.Random(20240607)
    seeds = _seeds()
    counts = {"ok": 0, "error": 0}
    for k in range(N_MUTANTS):
        kind, data = seeds[k % len(seeds)]
        mutant = data
        for _ in range(rng.choice((1, 1, 2, 3))):
            mutant = _mutate(rng, mutant)
        readers = [READERS[kind]]
        if k % 7 == 0:  # another reader too: a file of the wrong kind
            readers.append(OTHER[kind])
        for reader in readers:
            counts[_check(reader, mutant, f"mutant{k}.{kind}")] += 1
    # the corpus exercises both outcomes (a mutant that stays readable, and most that do not)
    assert counts["ok"] > 50 and counts["error"] > 500, counts


@settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(VOCAB_ZMX + VOCAB_SEQ),
            st.lists(
                st.one_of(
                    st.sampled_from(GARBAGE),
                    st.floats(allow_nan=True, allow_infinity=True).map(repr),
                    st.integers(-5, 20).map(str),
                    st.text(max_size=6),
                ),
                max_size=5,
            ),
        ),
        max_size=40,
    ),
    st.sampled_from(["zmx", "seq"]),
)
def test_random_command_soup(commands, kind):
    text = "\n".join(" ".join([c, *a]) for c, a in commands)
    reader = parse_zmx if kind == "zmx" else parse_seq
    _check(reader, text.encode("utf-8", errors="replace"), f"soup.{kind}")


@pytest.mark.parametrize("reader", [parse_zmx, parse_seq])
def test_empty_and_binary_files(reader):
    for data in (b"", b"\n\n  \n", b"\x00\x01\x02\xff" * 50, codecs.BOM_UTF16_LE + b"\x00\xd8"):
        assert _check(reader, data, "f") == "error"
