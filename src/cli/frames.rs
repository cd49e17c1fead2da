//! Which frames of an animation one `render` draws (`--frames`, `--frame-index-from`,
//! `--chunk`) and the file each goes to (`-o out/frame-####.png`): the contract a job
//! system's array task relies on, decided before any rendering.

use std::ops::Range;
use std::path::{Path, PathBuf};

/// `A..B` (end exclusive, like the language's ranges) or a single frame `N`.
pub(crate) fn parse_frames(s: &str) -> Result<Range<u32>, String> {
    let number = |n: &str| n.trim().parse::<u32>().map_err(|_| format!("`{n}` is not a frame number"));
    let range = match s.split_once("..") {
        Some((a, b)) => number(a)?..number(b)?,
        None => {
            let n = number(s)?;
            n..n.checked_add(1).ok_or_else(|| format!("frame {n} is past the last frame an animation may have"))?
        }
    };
    if range.is_empty() {
        return Err(format!("the frames {}..{} are none (the end is exclusive)", range.start, range.end));
    }
    Ok(range)
}

/// How a render picks its frames; see [`FrameChoice::select`].
pub(crate) struct FrameChoice<'a> {
    /// `--frames`.
    pub(crate) frames: Option<Range<u32>>,
    /// `--frame-index-from`: the environment variable holding this task's index.
    pub(crate) index_from: Option<&'a str>,
    /// `--chunk`: frames per task.
    pub(crate) chunk: u32,
}

impl FrameChoice<'_> {
    /// The frames to render of an animation of `declared` frames, reading the task index
    /// through `env`. Without `--frames`, every frame; with an index, task `i` takes the
    /// `i`-th run of `chunk` frames of that selection. An index past the last frame is an
    /// error, not an empty success: an array larger than the animation is a mistake in
    /// the job, and a task that renders nothing should not look like one that worked.
    pub(crate) fn select(&self, declared: u32, env: &dyn Fn(&str) -> Option<String>) -> Result<Range<u32>, String> {
        let all = self.frames.clone().unwrap_or(0..declared);
        if all.end > declared {
            let why = if declared == 1 {
                "the scene is a still: declare an animation with `render(frames = N)`".to_string()
            } else {
                format!("the scene's animation has frames 0..{declared}")
            };
            return Err(format!("cannot render frames {}..{}: {why}", all.start, all.end));
        }
        let Some(var) = self.index_from else {
            return Ok(all);
        };
        let value = env(var).ok_or_else(|| format!("--frame-index-from {var}: the variable `{var}` is not set"))?;
        let task: u32 = value
            .trim()
            .parse()
            .map_err(|_| format!("--frame-index-from {var}: `{value}` is not a task index (a whole number from 0)"))?;
        let start = u64::from(all.start) + u64::from(task) * u64::from(self.chunk);
        if start >= u64::from(all.end) {
            let tasks = (all.end - all.start).div_ceil(self.chunk);
            return Err(format!(
                "task {task} ({var}) of {} frames per task starts past frames {}..{}: they need tasks 0 to {}",
                self.chunk,
                all.start,
                all.end,
                tasks - 1
            ));
        }
        let end = (start + u64::from(self.chunk)).min(u64::from(all.end));
        Ok(start as u32..end as u32)
    }
}

/// A file name with a run of `#` standing for the frame number: what comes before the
/// last run, the run's length, and what comes after.
pub(crate) struct Pattern {
    /// Before the run.
    pub(crate) prefix: String,
    /// The run's length: frame numbers are zero-padded to it.
    pub(crate) width: usize,
    /// After the run.
    pub(crate) suffix: String,
}

impl Pattern {
    /// The pattern in `path`'s file name, if it has a `#`.
    pub(crate) fn of(path: &Path) -> Option<Pattern> {
        let name = path.file_name()?.to_string_lossy();
        let end = name.rfind('#')? + 1;
        let start = name[..end].trim_end_matches('#').len();
        Some(Pattern { prefix: name[..start].into(), width: end - start, suffix: name[end..].into() })
    }

    /// The file name of frame `n`: zero-padded to the run's length, more digits when the
    /// number needs them, as Blender names frames.
    pub(crate) fn name(&self, n: u32) -> String {
        format!("{}{n:0width$}{}", self.prefix, self.suffix, width = self.width)
    }

    /// The frame a file name is, when it is exactly what [`name`](Self::name) writes
    /// (`007` is not frame 7 of a one-`#` pattern).
    pub(crate) fn frame_of(&self, file: &str) -> Option<u32> {
        let digits = file.strip_prefix(&self.prefix)?.strip_suffix(&self.suffix)?;
        let n: u32 = digits.bytes().all(|b| b.is_ascii_digit()).then(|| digits.parse().ok())??;
        (self.name(n) == file).then_some(n)
    }
}

/// Whether the file name of `path` has a run of `#` for the frame number.
pub(crate) fn is_pattern(path: &Path) -> bool {
    Pattern::of(path).is_some()
}

/// `path` with the last run of `#` in its file name replaced by `frame` ([`Pattern::name`]).
pub(crate) fn frame_path(path: &Path, frame: u32) -> PathBuf {
    Pattern::of(path).map_or_else(|| path.to_path_buf(), |p| path.with_file_name(p.name(frame)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(vars: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| vars.iter().find(|(n, _)| *n == k).map(|(_, v)| v.to_string())
    }

    #[test]
    fn frame_ranges_parse_with_the_end_exclusive() {
        assert_eq!(parse_frames("0..48"), Ok(0..48));
        assert_eq!(parse_frames("7"), Ok(7..8));
        assert!(parse_frames("5..5").is_err());
        assert!(parse_frames("5..2").is_err());
        assert!(parse_frames("a..2").is_err());
        assert!(parse_frames("-1..2").is_err());
    }

    #[test]
    fn names_substitute_the_last_run_of_hashes_zero_padded() {
        assert_eq!(frame_path(Path::new("out/frame-####.png"), 7), Path::new("out/frame-0007.png"));
        assert_eq!(frame_path(Path::new("f#.png"), 12), Path::new("f12.png"));
        assert_eq!(frame_path(Path::new("a#b##.png"), 3), Path::new("a#b03.png"));
        assert_eq!(frame_path(Path::new("still.png"), 3), Path::new("still.png"));
        assert!(is_pattern(Path::new("x/f-##.png")) && !is_pattern(Path::new("x#/f.png")));
    }

    #[test]
    fn tasks_take_consecutive_chunks_of_the_selection() {
        let choice = FrameChoice { frames: None, index_from: Some("TASK"), chunk: 5 };
        assert_eq!(choice.select(48, &env(&[("TASK", "0")])), Ok(0..5));
        assert_eq!(choice.select(48, &env(&[("TASK", "9")])), Ok(45..48));
        assert!(choice.select(48, &env(&[("TASK", "10")])).unwrap_err().contains("tasks 0 to 9"));
        assert!(choice.select(48, &env(&[])).unwrap_err().contains("not set"));
        assert!(choice.select(48, &env(&[("TASK", "x")])).unwrap_err().contains("not a task index"));
        let within = FrameChoice { frames: Some(10..20), index_from: Some("TASK"), chunk: 4 };
        assert_eq!(within.select(48, &env(&[("TASK", "2")])), Ok(18..20));
    }

    #[test]
    fn frames_must_lie_in_the_animation() {
        let plain = FrameChoice { frames: None, index_from: None, chunk: 1 };
        assert_eq!(plain.select(1, &env(&[])), Ok(0..1));
        let past = FrameChoice { frames: Some(40..50), index_from: None, chunk: 1 };
        assert!(past.select(48, &env(&[])).unwrap_err().contains("frames 0..48"));
        assert!(past.select(1, &env(&[])).unwrap_err().contains("still"));
    }
}
