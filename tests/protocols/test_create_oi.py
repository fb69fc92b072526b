"""The Create 2 Open Interface codec (protocols/create_oi.py) against the spec's bytes."""

from __future__ import annotations

import math

import pytest

from protocols import create_oi as oi

SPEC_FRAME = bytes([19, 5, 29, 2, 25, 13, 0, 163])
"""The spec's stream example: packet 29 = 0x0219 = 537, packet 13 = 0."""
ENCODER_FRAME = oi.stream_frame({43: bytes([0x12, 0x34]), 44: bytes([0xFF, 0xFE])})


def test_stream_frame_reproduces_the_spec_example() -> None:
    assert oi.stream_frame({29: bytes([2, 25]), 13: bytes([0])}) == SPEC_FRAME


def test_stream_frame_sums_to_zero_and_checks_packet_lengths() -> None:
    assert sum(ENCODER_FRAME) % 256 == 0
    assert ENCODER_FRAME[:2] == bytes([19, 6])
    with pytest.raises(ValueError, match="packet 43 carries 2 data bytes"):
        oi.stream_frame({43: bytes([1])})
    with pytest.raises(ValueError, match="unsupported sensor packet 99"):
        oi.stream_frame({99: bytes([1])})


def test_packet_data_wraps_to_the_packet_width() -> None:
    assert oi.packet_data(43, 65536 + 5) == bytes([0, 5])
    assert oi.packet_data(44, -1) == bytes([0xFF, 0xFF])
    assert oi.packet_data(7, 3) == bytes([3])


@pytest.mark.parametrize(
    ("right", "left", "expected"),
    [
        (500, -500, "91 01 F4 FE 0C"),
        (0, 0, "91 00 00 00 00"),
        (-1, 200, "91 FF FF 00 C8"),
        (900, -32768, "91 01 F4 FE 0C"),
    ],
)
def test_drive_direct_bytes_right_wheel_first_and_clamped(
    right: int, left: int, expected: str
) -> None:
    assert oi.drive_direct(right, left) == bytes.fromhex(expected)


def test_parse_drive_direct_inverts_drive_direct() -> None:
    assert oi.parse_drive_direct(oi.drive_direct(-123, 456)[1:]) == (-123, 456)
    with pytest.raises(ValueError, match="4 data bytes"):
        oi.parse_drive_direct(bytes(3))


def test_stream_request_and_pause_resume_bytes() -> None:
    assert oi.stream_request([43, 44]) == bytes([148, 2, 43, 44])
    assert oi.pause_resume(False) == bytes([150, 0])
    assert oi.pause_resume(True) == bytes([150, 1])


def packets(parser: oi.StreamParser, data: bytes) -> list[dict[int, int]]:
    return [f.packets for f in parser.feed(data)]


def test_parser_decodes_the_spec_example() -> None:
    assert packets(oi.StreamParser(), SPEC_FRAME) == [{29: 537, 13: 0}]


def test_parser_joins_a_frame_split_across_feeds() -> None:
    parser = oi.StreamParser()
    stream = ENCODER_FRAME + SPEC_FRAME
    frames = [f.packets for byte in stream for f in parser.feed(bytes([byte]))]
    assert frames == [{43: 0x1234, 44: 0xFFFE}, {29: 537, 13: 0}]
    assert (parser.resyncs, parser.bad_checksums, parser.bad_frames) == (0, 0, 0)


def test_parser_skips_garbage_before_a_frame() -> None:
    parser = oi.StreamParser()
    assert packets(parser, bytes([0, 255, 7, 1]) + ENCODER_FRAME) == [{43: 0x1234, 44: 0xFFFE}]
    assert parser.resyncs == 4


def test_parser_counts_and_skips_a_bad_checksum() -> None:
    parser = oi.StreamParser()
    corrupt = SPEC_FRAME[:-1] + bytes([SPEC_FRAME[-1] ^ 1])
    assert packets(parser, corrupt + ENCODER_FRAME) == [{43: 0x1234, 44: 0xFFFE}]
    assert parser.bad_checksums == 1
    assert parser.resyncs == len(SPEC_FRAME) - 1


def test_parser_recovers_from_a_truncated_frame() -> None:
    parser = oi.StreamParser()
    assert packets(parser, ENCODER_FRAME[:5]) == []
    assert packets(parser, SPEC_FRAME + ENCODER_FRAME) == [
        {29: 537, 13: 0},
        {43: 0x1234, 44: 0xFFFE},
    ]
    assert parser.bad_checksums == 1


def test_parser_rejects_a_good_checksum_over_unknown_packets() -> None:
    parser = oi.StreamParser()
    unknown = bytes([19, 2, 99, 0])
    assert packets(parser, unknown + bytes([-sum(unknown) & 0xFF]) + SPEC_FRAME) == [
        {29: 537, 13: 0}
    ]
    assert parser.bad_frames == 1


def test_parser_never_raises_on_random_bytes() -> None:
    parser = oi.StreamParser()
    noise = bytes((i * 7919 + 13) % 256 for i in range(5000))
    for start in range(0, len(noise), 37):
        parser.feed(noise[start : start + 37])
    assert packets(parser, bytes(300) + SPEC_FRAME)[-1] == {29: 537, 13: 0}


@pytest.mark.parametrize(
    ("new", "old", "delta"),
    [
        (5, 65530, 11),
        (65530, 5, -11),
        (1000, 900, 100),
        (900, 1000, -100),
        (-32768, 32767, 1),
        (32767, -32768, -1),
    ],
)
def test_encoder_delta_across_rollover(new: int, old: int, delta: int) -> None:
    assert oi.encoder_delta(new, old) == delta


def test_mm_per_count_of_the_72_mm_wheel() -> None:
    assert oi.mm_per_count(0.072) == pytest.approx(math.pi * 72 / 508.8)
    assert oi.mm_per_count(0.072) == pytest.approx(0.4446, abs=1e-4)


def test_a_parser_that_knows_its_packets_drops_a_stray_header_at_once() -> None:
    """``19 255`` would hold a general parser for 258 bytes; the driver's knows n is 6."""
    parser = oi.StreamParser([oi.LEFT_ENCODER, oi.RIGHT_ENCODER])
    assert packets(parser, bytes([19, 255]) + ENCODER_FRAME) == [{43: 0x1234, 44: 0xFFFE}]
    assert parser.resyncs == 2


def test_a_parser_that_knows_its_packets_refuses_a_frame_of_others_of_the_same_length() -> None:
    parser = oi.StreamParser([oi.LEFT_ENCODER, oi.RIGHT_ENCODER])
    others = oi.stream_frame({29: b"\x02\x19", 43: b"\x00\x02"})
    assert others[1] == ENCODER_FRAME[1]
    assert packets(parser, others + ENCODER_FRAME) == [{43: 0x1234, 44: 0xFFFE}]
    assert parser.bad_frames == 1


def test_each_frame_says_how_many_were_refused_before_it() -> None:
    parser = oi.StreamParser([oi.LEFT_ENCODER, oi.RIGHT_ENCODER])
    corrupt = ENCODER_FRAME[:-1] + bytes([ENCODER_FRAME[-1] ^ 1])
    frames = parser.feed(ENCODER_FRAME + corrupt + corrupt + ENCODER_FRAME + ENCODER_FRAME)
    assert [f.lost for f in frames] == [0, 2, 0]
