//! Small writers of PX4 ULog and ArduPilot DataFlash logs holding one gyro topic, for the
//! tests and the bench (no product code writes these formats).

#![allow(dead_code)]

/// One gyro sample: time (µs), instance, rates (rad/s), temperature (°C).
#[derive(Debug, Clone, Copy)]
pub struct GyroSample {
    pub t_us: u64,
    pub instance: u8,
    pub rate: [f32; 3],
    pub temp_c: f32,
}

/// A ULog whose topic `sensor_gyro` holds instances `0..instances` and the `samples`.
pub struct Ulog {
    pub bytes: Vec<u8>,
}

fn ulog_msg(out: &mut Vec<u8>, ty: u8, payload: &[u8]) {
    out.extend_from_slice(&(payload.len() as u16).to_le_bytes());
    out.push(ty);
    out.extend_from_slice(payload);
}

impl Ulog {
    /// Header, flag bits, the `sensor_gyro` format and one subscription per instance.
    pub fn new(instances: u8) -> Self {
        let mut b = b"ULog\x01\x12\x35".to_vec();
        b.push(1);
        b.extend_from_slice(&0u64.to_le_bytes());
        ulog_msg(&mut b, b'B', &[0u8; 40]);
        ulog_msg(
            &mut b,
            b'F',
            b"sensor_gyro:uint64_t timestamp;uint32_t device_id;float x;float y;float z;\
              float temperature;uint32_t error_count;",
        );
        for k in 0..instances {
            let mut p = vec![k];
            p.extend_from_slice(&(k as u16).to_le_bytes());
            p.extend_from_slice(b"sensor_gyro");
            ulog_msg(&mut b, b'A', &p);
        }
        Ulog { bytes: b }
    }

    /// One `sensor_gyro` message (the instance is its subscription's message id).
    pub fn push(&mut self, s: GyroSample) {
        let mut p = Vec::with_capacity(34);
        p.extend_from_slice(&(s.instance as u16).to_le_bytes());
        p.extend_from_slice(&s.t_us.to_le_bytes());
        p.extend_from_slice(&(0x2_0000 + s.instance as u32).to_le_bytes());
        for v in s.rate.iter().chain([&s.temp_c]) {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(&0u32.to_le_bytes());
        ulog_msg(&mut self.bytes, b'D', &p);
    }
}

/// A DataFlash log whose message `IMU` (ArduPilot's layout) holds the samples.
pub struct DataFlash {
    pub bytes: Vec<u8>,
}

const IMU_TYPE: u8 = 0x81;
const IMU_FORMAT: &str = "QBffffffIIfBBHH";
const IMU_LABELS: &str = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";
/// Bytes of an `IMU` message, header included.
pub const IMU_LEN: usize = 3 + 8 + 1 + 6 * 4 + 2 * 4 + 4 + 2 + 2 * 2;

fn fmt(out: &mut Vec<u8>, ty: u8, len: u8, name: &str, format: &str, labels: &str) {
    out.extend_from_slice(&[0xA3, 0x95, 0x80]);
    let mut p = [0u8; 86];
    p[0] = ty;
    p[1] = len;
    p[2..2 + name.len()].copy_from_slice(name.as_bytes());
    p[6..6 + format.len()].copy_from_slice(format.as_bytes());
    p[22..22 + labels.len()].copy_from_slice(labels.as_bytes());
    out.extend_from_slice(&p);
}

impl DataFlash {
    /// The FMT of FMT and of IMU.
    pub fn new() -> Self {
        let mut b = Vec::new();
        fmt(
            &mut b,
            0x80,
            89,
            "FMT",
            "BBnNZ",
            "Type,Length,Name,Format,Labels",
        );
        fmt(
            &mut b,
            IMU_TYPE,
            IMU_LEN as u8,
            "IMU",
            IMU_FORMAT,
            IMU_LABELS,
        );
        DataFlash { bytes: b }
    }

    /// One `IMU` message.
    pub fn push(&mut self, s: GyroSample) {
        let b = &mut self.bytes;
        b.extend_from_slice(&[0xA3, 0x95, IMU_TYPE]);
        b.extend_from_slice(&s.t_us.to_le_bytes());
        b.push(s.instance);
        for v in s.rate.iter().chain(&[0.0, 0.0, -9.81]) {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&[0u8; 8]);
        b.extend_from_slice(&s.temp_c.to_le_bytes());
        b.extend_from_slice(&[1, 1]);
        b.extend_from_slice(&[0u8; 4]);
    }
}

impl Default for DataFlash {
    fn default() -> Self {
        Self::new()
    }
}
