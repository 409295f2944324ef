//! What a sweep's files belong to: the [`Stamp`] of a sweep (shpb version, `--set` as written and
//! the [`Identity`]: the scene and the files it resolves by content, the swept values, the shard).
//! The checkpoint carries it in its header and the study file in its root attributes;
//! `shpb sweep --resume` and `shpb merge` compare stamps and name what differs.

use shpb_input::provenance::{InputFile, sha256_hex};
pub use shpb_output::study::Identity;
use shpb_output::study::{parse_sha256sum_line, sha256sum_line};
use std::path::Path;

/// A sweep's stamp: the version of shpb, the `--set` specifications as written and the identity.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stamp {
    /// The version of shpb.
    pub shpb_version: String,
    /// The `--set` specifications as written (without the shard).
    pub set: Vec<String>,
    /// The identity.
    pub identity: Identity,
}

/// SHA-256 of the swept keys and their values in order (`key=v1,v2,…` per line, values as
/// written after alias resolution and range expansion), so `pressure=5psi:10psi:2` and
/// `striker.pressure=5psi,10psi` are the same sweep.
pub fn set_sha256<'a>(axes: impl IntoIterator<Item = (&'a str, &'a [String])>) -> String {
    let text: String = axes
        .into_iter()
        .map(|(key, labels)| format!("{key}={}\n", labels.join(",")))
        .collect();
    sha256_hex(text.as_bytes())
}

/// The fingerprint shared by every shard of one sweep: SHA-256 over the version, the scene's and
/// the other input files' contents (not their paths: a sweep resumed from another directory is
/// the same sweep) and [`set_sha256`].
pub fn sweep_id(version: &str, scene: &InputFile, inputs: &[InputFile], set_sha: &str) -> String {
    let mut shas: Vec<&str> = inputs.iter().map(|f| f.sha256.as_str()).collect();
    shas.sort_unstable();
    let text = format!(
        "shpb {version}\nscene {}\ninputs {}\nset {set_sha}\n",
        scene.sha256,
        shas.join(" ")
    );
    sha256_hex(text.as_bytes())
}

impl Stamp {
    /// The stamp of a sweep of `scene` whose points resolved `files` (as returned by
    /// `sweep::check_points`: the scene first), swept as `set` (whose keys and values hash to
    /// `set_sha`, [`set_sha256`]), shard `k/n` of `runs_total` runs, by this version of shpb.
    pub fn new(
        scene: &Path,
        files: &[InputFile],
        set: &[String],
        set_sha: String,
        shard: (usize, usize),
        runs_total: u64,
    ) -> Stamp {
        let version = env!("CARGO_PKG_VERSION").to_string();
        let scene_file = files
            .iter()
            .find(|f| f.path == scene)
            .cloned()
            .unwrap_or_else(|| InputFile {
                path: scene.to_path_buf(),
                sha256: std::fs::read(scene)
                    .map(|b| sha256_hex(&b))
                    .unwrap_or_default(),
            });
        let inputs: Vec<InputFile> = files.iter().filter(|f| f.path != scene).cloned().collect();
        Stamp {
            identity: Identity {
                sweep_id: sweep_id(&version, &scene_file, &inputs, &set_sha),
                scene: scene_file,
                inputs,
                set_sha256: set_sha,
                shard: (shard.0 as u64, shard.1 as u64),
                runs_total,
            },
            set: set.to_vec(),
            shpb_version: version,
        }
    }

    /// The stamp of a study file: its version, its specifications without the shard line and its
    /// identity (`None` for a file written before shpb recorded one).
    pub fn of_file(
        shpb_version: &str,
        sweep: &[String],
        identity: Option<&Identity>,
    ) -> Option<Stamp> {
        Some(Stamp {
            shpb_version: shpb_version.to_string(),
            set: sweep
                .iter()
                .filter(|s| !s.starts_with("shard "))
                .cloned()
                .collect(),
            identity: identity?.clone(),
        })
    }

    /// Whether `other` is the same sweep (the same [`Identity::sweep_id`]; shards may differ).
    pub fn same_sweep(&self, other: &Stamp) -> bool {
        self.identity.sweep_id == other.identity.sweep_id
    }

    /// What differs between `self` (`then`: the checkpoint's or file's) and `now`, one phrase
    /// each (empty when they are the same sweep and shard).
    pub fn differences(&self, now: &Stamp) -> Vec<String> {
        let (a, b) = (&self.identity, &now.identity);
        let mut out = Vec::new();
        if self.shpb_version != now.shpb_version {
            out.push(format!(
                "shpb version {} then, {} now",
                self.shpb_version, now.shpb_version
            ));
        }
        if a.scene.sha256 != b.scene.sha256 {
            let paths = if a.scene.path == b.scene.path {
                a.scene.path.display().to_string()
            } else {
                format!(
                    "{} then, {} now",
                    a.scene.path.display(),
                    b.scene.path.display()
                )
            };
            out.push(format!(
                "the content of the scene {paths} (sha256 {} then, {} now)",
                short(&a.scene.sha256),
                short(&b.scene.sha256)
            ));
        }
        let mut then: Vec<&str> = a.inputs.iter().map(|f| f.sha256.as_str()).collect();
        let mut here: Vec<&str> = b.inputs.iter().map(|f| f.sha256.as_str()).collect();
        then.sort_unstable();
        here.sort_unstable();
        if then != here {
            for f in &a.inputs {
                if b.inputs.contains(f) {
                    continue;
                }
                match b.inputs.iter().find(|g| g.path == f.path) {
                    Some(g) => out.push(format!(
                        "the content of {} (sha256 {} then, {} now)",
                        f.path.display(),
                        short(&f.sha256),
                        short(&g.sha256)
                    )),
                    None => out.push(format!(
                        "{} (sha256 {}) was read then, not now",
                        f.path.display(),
                        short(&f.sha256)
                    )),
                }
            }
            for g in &b.inputs {
                if !a.inputs.iter().any(|f| f.path == g.path) {
                    out.push(format!(
                        "{} (sha256 {}) is read now, not then",
                        g.path.display(),
                        short(&g.sha256)
                    ));
                }
            }
        }
        if a.set_sha256 != b.set_sha256 {
            out.push(format!(
                "the swept values (--set {} then, --set {} now)",
                self.set.join(" --set "),
                now.set.join(" --set ")
            ));
        }
        if out.is_empty() && a.sweep_id != b.sweep_id {
            out.push("the sweep's fingerprint (sweep_id)".to_string());
        }
        if a.shard != b.shard {
            out.push(format!(
                "the shard ({}/{} then, {}/{} now)",
                a.shard.0, a.shard.1, b.shard.0, b.shard.1
            ));
        }
        out
    }

    /// The header of a checkpoint: `# key: value` lines.
    pub fn checkpoint_header(&self) -> String {
        let id = &self.identity;
        let mut lines = vec![
            CHECKPOINT_TITLE.to_string(),
            format!("# shpb_version: {}", self.shpb_version),
            format!("# sweep_id: {}", id.sweep_id),
            format!("# scene_file: {}", sha256sum_line(&id.scene)),
        ];
        lines.extend(
            id.inputs
                .iter()
                .map(|f| format!("# input_file: {}", sha256sum_line(f))),
        );
        lines.push(format!("# set_sha256: {}", id.set_sha256));
        lines.extend(self.set.iter().map(|s| format!("# set: {s}")));
        lines.push(format!("# shard: {}/{}", id.shard.0, id.shard.1));
        lines.push(format!("# runs_total: {}", id.runs_total));
        lines.join("\n") + "\n"
    }

    /// Reads the stamp back from a checkpoint's `#` lines; `None` when they are not a complete
    /// header of this format (a checkpoint of an older shpb, a damaged file).
    pub fn from_checkpoint_header<'a>(lines: impl IntoIterator<Item = &'a str>) -> Option<Stamp> {
        let mut lines = lines.into_iter();
        if lines.next()? != CHECKPOINT_TITLE {
            return None;
        }
        let (mut version, mut sweep_id, mut scene, mut set_sha, mut shard, mut runs) =
            (None, None, None, None, None, None);
        let (mut inputs, mut set) = (Vec::new(), Vec::new());
        for line in lines {
            let (key, value) = line.strip_prefix("# ")?.split_once(": ")?;
            match key {
                "shpb_version" => version = Some(value.to_string()),
                "sweep_id" => sweep_id = Some(value.to_string()),
                "scene_file" => scene = Some(parse_sha256sum_line(value)?),
                "input_file" => inputs.push(parse_sha256sum_line(value)?),
                "set_sha256" => set_sha = Some(value.to_string()),
                "set" => set.push(value.to_string()),
                "shard" => {
                    let (k, n) = value.split_once('/')?;
                    shard = Some((k.parse().ok()?, n.parse().ok()?));
                }
                "runs_total" => runs = Some(value.parse().ok()?),
                _ => return None,
            }
        }
        Some(Stamp {
            shpb_version: version?,
            set,
            identity: Identity {
                sweep_id: sweep_id?,
                scene: scene?,
                inputs,
                set_sha256: set_sha?,
                shard: shard?,
                runs_total: runs?,
            },
        })
    }
}

/// The first line of a checkpoint.
pub const CHECKPOINT_TITLE: &str = "# shpb sweep checkpoint";

/// The first 12 hex digits of a SHA-256, for messages.
fn short(sha: &str) -> &str {
    &sha[..sha.len().min(12)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{Axis, axes_sha256, parse_axis};

    fn file(path: &str, content: &str) -> InputFile {
        InputFile {
            path: path.into(),
            sha256: sha256_hex(content.as_bytes()),
        }
    }

    fn stamp(scene: &str, bars: &str, set: &[&str], shard: (usize, usize)) -> Stamp {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let axes: Vec<Axis> = set.iter().map(|s| parse_axis(s).unwrap()).collect();
        Stamp::new(
            Path::new("s.toml"),
            &[file("s.toml", scene), file("bars/b.toml", bars)],
            &set,
            axes_sha256(&axes),
            shard,
            2,
        )
    }

    #[test]
    fn the_same_sweep_has_one_id_and_each_change_is_named() {
        let a = stamp("kind=1", "bars", &["pressure=5psi,10psi"], (1, 2));
        // Another shard, an alias, the range form: the same sweep.
        let b = stamp("kind=1", "bars", &["striker.pressure=5psi:10psi:2"], (2, 2));
        assert!(a.same_sweep(&b));
        assert_eq!(a.differences(&b), ["the shard (1/2 then, 2/2 now)"]);
        assert!(a.differences(&a).is_empty());
        let scene = stamp("kind=2", "bars", &["pressure=5psi,10psi"], (1, 2));
        assert!(!a.same_sweep(&scene));
        let d = a.differences(&scene);
        assert!(
            d.len() == 1 && d[0].contains("the content of the scene s.toml"),
            "{d:?}"
        );
        let bars = stamp("kind=1", "other bars", &["pressure=5psi,10psi"], (1, 2));
        let d = a.differences(&bars);
        assert!(d.len() == 1 && d[0].contains("bars/b.toml"), "{d:?}");
        let set = stamp("kind=1", "bars", &["pressure=5psi,11psi"], (1, 2));
        let d = a.differences(&set);
        assert!(
            d.len() == 1 && d[0].contains("pressure=5psi,11psi"),
            "{d:?}"
        );
        let mut version = a.clone();
        version.shpb_version = "0.0.1".into();
        assert!(a.differences(&version)[0].contains("shpb version"));
    }

    #[test]
    fn a_stamp_round_trips_through_a_checkpoint_header() {
        let a = stamp(
            "kind=1",
            "bars",
            &["pressure=5psi,10psi", "law=hertz"],
            (1, 2),
        );
        let header = a.checkpoint_header();
        assert_eq!(
            Stamp::from_checkpoint_header(header.lines()),
            Some(a.clone())
        );
        // The header of an older shpb, or a torn one, is not a stamp.
        assert_eq!(
            Stamp::from_checkpoint_header(["# shpb sweep checkpoint; scene=s.toml; set=p=1"]),
            None
        );
        let torn: Vec<&str> = header.lines().take(3).collect();
        assert_eq!(Stamp::from_checkpoint_header(torn), None);
    }
}
