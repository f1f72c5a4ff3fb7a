//! The Kalibr noise file of `gyrotherm allan --kalibr` ([`crate::allan::kalibr`]): the ROS
//! topic it names.

use crate::setting_rule::{Rule, SettingError};

/// The topic written when none is given: Kalibr's own examples name their IMU `/imu0`.
pub const DEFAULT_ROSTOPIC: &str = "/imu0";

/// Check a ROS topic name (`--rostopic`): a letter or `/` first, then ASCII letters, digits,
/// `_` and `/`, a letter after each `/`, no trailing `/` (the ROS graph-resource name
/// rules). The name is
/// written into a YAML file, so these rules also keep it one plain scalar.
pub fn parse_rostopic(s: &str) -> Result<String, SettingError> {
    let bad = || SettingError::Invalid {
        setting: "rostopic",
        value: format!("{s:?}"),
        rule: Rule::RosTopic,
    };
    let b = s.as_bytes();
    let first_ok = b
        .first()
        .is_some_and(|c| c.is_ascii_alphabetic() || *c == b'/');
    let rest_ok = b
        .iter()
        .all(|c| c.is_ascii_alphanumeric() || *c == b'_' || *c == b'/');
    let after_slash_ok = b
        .windows(2)
        .all(|w| w[0] != b'/' || w[1].is_ascii_alphabetic());
    let ok = first_ok && rest_ok && after_slash_ok && b.len() <= 256 && b.last() != Some(&b'/');
    ok.then(|| s.to_owned()).ok_or_else(bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ros_names_are_taken_and_others_refused() {
        for good in ["/imu0", "imu", "/sensors/imu", "/a_b/c9"] {
            assert_eq!(parse_rostopic(good).unwrap(), good);
        }
        for bad in [
            "", "/", "0imu", "/imu/", "//imu", "/imu 0", "/imu: x", "/imu\n#", "/é", "/9a",
        ] {
            assert!(parse_rostopic(bad).is_err(), "{bad:?}");
        }
    }
}
