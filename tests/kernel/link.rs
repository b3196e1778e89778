//! The link's wire format (`palpate_kernel::link`): frames and payloads
//! round-trip bit for bit, every corruption, truncation and out-of-range
//! field is refused with its error, a byte stream with garbage, splits and
//! corrupted frames is reassembled, and the stated frame sizes hold the
//! 1 Mbit/s serial budget.

use nalgebra::Vector3;
use palpate_kernel::haptic::{ToolAction, ToolInput};
use palpate_kernel::link::command::{MAX_COMMAND_FRAME_BYTES, command_payload_bytes};
use palpate_kernel::link::frame::{FRAME_OVERHEAD_BYTES, MAX_FRAME_BYTES};
use palpate_kernel::link::update::{MAX_UPDATE_FRAME_BYTES, update_payload_bytes};
use palpate_kernel::link::{
    Command, FrameError, FrameKind, FrameReader, FrameView, LINK_REGIONS, LINK_SAMPLES,
    LINK_TRIANGLES, LINK_VERTICES, LocalContact, PayloadError, Region, RegionVertex, Update,
};

type Up = Update<LINK_REGIONS, LINK_VERTICES, LINK_TRIANGLES>;
type Cmd = Command<LINK_REGIONS, LINK_SAMPLES>;

/// A full region of tool `tool`: every count at capacity, distinct reals.
fn region(tool: u8, held: bool) -> Region<LINK_VERTICES, LINK_TRIANGLES> {
    let x = |i: usize| f32::from(tool) + 0.001 * i as f32;
    let mut r = Region {
        tool,
        held,
        grip: held && tool == 1,
        contact: LocalContact {
            stiffness_tensor_n_per_m: core::array::from_fn(|i| 100.0 + x(i)),
            normal: [0.0, 0.0, 1.0],
            tip_m: [x(1), x(2), x(3)],
            force_n: [0.0, 0.0, -x(4)],
            scale: 0.75,
            offset_n: -0.01,
        },
        ..Region::default()
    };
    for i in 0..LINK_VERTICES {
        let v = RegionVertex {
            position_m: [x(i), x(i + 1), 0.03],
            velocity_m_s: [0.0, 0.0, -x(i)],
        };
        r.vertices.push(v).expect("capacity");
    }
    for t in [[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]] {
        r.triangles.push(t).expect("capacity");
    }
    r
}

fn full_update() -> Up {
    let mut u = Up {
        tick: 99,
        period_ticks: 10,
        ..Up::default()
    };
    for tool in 0..LINK_REGIONS as u8 {
        u.regions
            .push(region(tool, tool % 2 == 1))
            .expect("capacity");
    }
    u
}

fn encode(u: &Up, sequence: u32) -> Vec<u8> {
    let mut out = vec![0u8; MAX_FRAME_BYTES];
    let n = u.encode(sequence, &mut out).expect("encode");
    out.truncate(n);
    out
}

#[test]
fn frame_sizes_fit_a_1_mbit_serial_link_at_100_hz() {
    // 8N1: 10 bits per byte, 100 000 bytes/s each way; one update and one
    // command frame per 10 ms each way.
    assert_eq!(MAX_UPDATE_FRAME_BYTES, 982);
    assert_eq!(MAX_COMMAND_FRAME_BYTES, 588);
    const { assert!(MAX_UPDATE_FRAME_BYTES <= 1000 && MAX_COMMAND_FRAME_BYTES <= 1000) };
    let full = encode(&full_update(), 0);
    assert_eq!(full.len(), MAX_UPDATE_FRAME_BYTES);
    assert_eq!(
        full.len(),
        update_payload_bytes(LINK_REGIONS, LINK_VERTICES, LINK_TRIANGLES) + FRAME_OVERHEAD_BYTES
    );
    let mut probe = full_update();
    probe.regions.truncate(1);
    assert_eq!(encode(&probe, 0).len(), 262);
    assert_eq!(command_payload_bytes(1, 1), 6 + 13 + 12);
}

#[test]
fn update_round_trips_bit_for_bit() {
    let u = full_update();
    let bytes = encode(&u, 0xdead_beef);
    let (frame, total) = FrameView::parse(&bytes).expect("frame");
    assert_eq!(total, bytes.len());
    assert_eq!(frame.kind, FrameKind::Update);
    assert_eq!(frame.sequence, 0xdead_beef);
    assert_eq!(Up::decode(frame.payload), Ok(u));
}

#[test]
fn command_round_trips_with_actions_and_blades() {
    let mut c = Cmd::new(7);
    for k in 0..LINK_SAMPLES {
        let at = |p: usize| Vector3::new(p as f32, k as f32 * 1e-4, 0.031);
        let blade = Vector3::new(0.0, 0.0, -0.01);
        c.samples
            .push([
                ToolInput::touch(at(0)),
                ToolInput {
                    position_m: at(1),
                    action: ToolAction::Grip,
                },
                ToolInput {
                    position_m: at(2),
                    action: ToolAction::Cut { blade_m: blade },
                },
                ToolInput::touch(at(3)),
            ])
            .expect("capacity");
    }
    let mut out = vec![0u8; MAX_FRAME_BYTES];
    let n = c.encode(3, &mut out).expect("encode");
    assert_eq!(n, MAX_COMMAND_FRAME_BYTES);
    let (frame, _) = FrameView::parse(&out[..n]).expect("frame");
    assert_eq!(frame.kind, FrameKind::Command);
    assert_eq!(Cmd::decode(frame.payload), Ok(c.clone()));
    // A NaN position is refused at the encoder, never sent.
    c.samples[3][0].position_m.x = f32::NAN;
    assert!(c.encode(4, &mut out).is_err());
    assert!(Cmd::new(0).encode(0, &mut out).is_err(), "an empty batch");
}

#[test]
fn every_flipped_bit_and_every_truncation_is_refused() {
    let bytes = encode(&full_update(), 5);
    for cut in 0..bytes.len() {
        assert!(
            matches!(
                FrameView::parse(&bytes[..cut]),
                Err(FrameError::Short { .. })
            ),
            "prefix of {cut} bytes"
        );
    }
    // CRC-32 detects every single-bit error.
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            match FrameView::parse(&b) {
                Err(_) => {}
                Ok(_) => panic!("byte {i} bit {bit} flipped and accepted"),
            }
        }
    }
    let mut b = bytes.clone();
    b[0] = b'X';
    assert_eq!(FrameView::parse(&b), Err(FrameError::BadMagic));
    let mut b = bytes.clone();
    b[4..6].copy_from_slice(&u16::MAX.to_le_bytes());
    assert_eq!(FrameView::parse(&b), Err(FrameError::BadLength));
}

/// `payload` re-framed (a valid CRC) and decoded: what a sender with a bug
/// would make the controller see.
fn decode_payload(payload: &[u8]) -> Result<Up, PayloadError> {
    Up::decode(payload)
}

#[test]
fn payloads_out_of_range_are_refused() {
    let bytes = encode(&full_update(), 0);
    let (frame, _) = FrameView::parse(&bytes).expect("frame");
    let good = frame.payload.to_vec();
    // Header 8, then region 0: tool, flags, nv, nt, 80 bytes of reals, 6
    // vertices of 24 bytes, then its triangles.
    let tri0 = 8 + 4 + 80 + 6 * 24;
    let cases: [(&str, usize, u8, PayloadError); 7] = [
        ("zero period", 4, 0, PayloadError::OutOfRange),
        ("5 regions of 4", 6, 5, PayloadError::OutOfRange),
        ("tool 9 of 4", 8, 9, PayloadError::OutOfRange),
        ("tool 0 twice", 8 + 240, 0, PayloadError::OutOfRange),
        ("grip without held", 9, 2, PayloadError::OutOfRange),
        ("7 vertices of 6", 10, 7, PayloadError::OutOfRange),
        (
            "a triangle's vertex 6 of 6",
            tri0,
            6,
            PayloadError::OutOfRange,
        ),
    ];
    for (what, at, value, error) in cases {
        let mut p = good.clone();
        p[at] = value;
        if at == 4 {
            p[5] = 0;
        }
        assert_eq!(decode_payload(&p), Err(error), "{what}");
    }
    let mut nan = good.clone();
    nan[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(decode_payload(&nan), Err(PayloadError::OutOfRange), "NaN");
    let mut alpha = good.clone();
    alpha[12 + 18 * 4..12 + 19 * 4].copy_from_slice(&1.5f32.to_le_bytes());
    assert_eq!(decode_payload(&alpha), Err(PayloadError::OutOfRange), "α");
    let mut long = good.clone();
    long.push(0);
    assert_eq!(decode_payload(&long), Err(PayloadError::BadLength));
    for cut in 0..good.len() {
        assert_eq!(
            decode_payload(&good[..cut]),
            Err(PayloadError::Short),
            "{cut}"
        );
    }
}

#[test]
fn a_stream_with_garbage_splits_and_a_corrupted_frame_is_reassembled() {
    let frames: Vec<Vec<u8>> = (0..4).map(|s| encode(&full_update(), s)).collect();
    let mut stream = b"PLxx\x00garbage".to_vec();
    for (s, f) in frames.iter().enumerate() {
        let mut f = f.clone();
        if s == 2 {
            f[300] ^= 0x10; // corrupted on the line
        }
        stream.extend_from_slice(&f);
    }
    let mut reader = FrameReader::<{ 2 * MAX_FRAME_BYTES }>::new();
    let mut sequences = Vec::new();
    for chunk in stream.chunks(97) {
        let mut rest = chunk;
        while !rest.is_empty() {
            let n = reader.push(rest);
            rest = &rest[n..];
            while let Some(frame) = reader.next_frame() {
                assert_eq!(Up::decode(frame.payload), Ok(full_update()));
                sequences.push(frame.sequence);
            }
        }
    }
    assert_eq!(sequences, [0, 1, 3], "frame 2 dropped, the others whole");
    assert!(reader.corrupt() >= 2, "the garbage and frame 2 counted");
}
