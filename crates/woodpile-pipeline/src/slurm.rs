//! SLURM job scripts for a sharded sweep: an array job whose task I runs shard I/N, and a merge
//! job that starts only if every array task succeeded (`--dependency=afterok`). Pure text
//! generation; the CLI writes the files and the user (or `make slurm-test`) submits them.

use std::path::Path;

/// What the scripts need to know.
#[derive(Debug, Clone)]
pub struct SlurmJob<'a> {
    /// The sweep stage.
    pub stage: &'a str,
    /// Array tasks (= shards).
    pub tasks: usize,
    /// `--partition`, if any.
    pub partition: Option<&'a str>,
    /// `--time` limit per task, if any (SLURM syntax, e.g. `01:00:00`).
    pub time: Option<&'a str>,
    /// CPUs per task; rayon uses them all.
    pub cpus: usize,
    /// The `woodpile` binary (absolute: jobs start in another shell).
    pub binary: &'a Path,
    /// The project directory the jobs `cd` into (absolute).
    pub workdir: &'a Path,
    /// `--pipeline` (relative to `workdir`, or absolute).
    pub pipeline: &'a Path,
    /// `--results` (shared by every task; relative to `workdir`, or absolute).
    pub results: &'a Path,
    /// Directory of the jobs' log files.
    pub logs: &'a Path,
}

fn quote(path: &Path) -> String {
    format!("'{}'", path.display().to_string().replace('\'', "'\\''"))
}

/// Most CPUs a task may ask for: more than any node has.
pub const MAX_CPUS: usize = 1024;

/// `path` as an `#SBATCH --output` value: in double quotes (sbatch splits its lines at spaces
/// otherwise), with `%` doubled (sbatch reads `%j`, `%A` as the job's numbers). A path with a
/// double quote or a backslash is refused by [`SlurmJob::validate`].
fn sbatch_path(path: &Path) -> String {
    path.display().to_string().replace('%', "%%")
}

impl SlurmJob<'_> {
    /// Refuses what a script cannot carry safely: a value with a character outside
    /// `[A-Za-z0-9-_:.,+]` (partition, time), or a path with a control character such as a
    /// newline, which no quoting protects in an `#SBATCH` line. The error names the flag.
    pub fn validate(&self) -> Result<(), String> {
        for (flag, value) in [("--partition", self.partition), ("--time", self.time)] {
            if let Some(v) = value {
                if v.is_empty()
                    || !v
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-_:.,+".contains(c))
                {
                    return Err(format!(
                        "{flag} `{}`: only letters, digits and -_:.,+ may go into a SLURM script",
                        v.escape_debug()
                    ));
                }
            }
        }
        if self.cpus == 0 || self.cpus > MAX_CPUS {
            return Err(format!(
                "--cpus {}: a task takes from 1 to {MAX_CPUS} CPUs",
                self.cpus
            ));
        }
        if self.stage.starts_with('-') {
            return Err(format!(
                "stage `{}`: a name that starts with `-` would be read as a flag",
                self.stage.escape_debug()
            ));
        }
        let logs = self.logs.display().to_string();
        if logs.contains(['"', '\\']) {
            return Err(format!(
                "--out `{}`: a quote or a backslash cannot go into an #SBATCH --output path",
                logs.escape_debug()
            ));
        }
        let paths = [
            ("the woodpile binary", self.binary),
            ("the working directory", self.workdir),
            ("--pipeline", self.pipeline),
            ("--results", self.results),
            ("--out", self.logs),
        ];
        for (what, path) in paths {
            let text = path.display().to_string();
            if text.chars().any(char::is_control) {
                return Err(format!(
                    "{what} `{}`: a path with a control character (a newline, a tab) cannot go into a SLURM script",
                    text.escape_debug()
                ));
            }
        }
        Ok(())
    }

    fn header(&self, name: &str, log: &str) -> String {
        let mut h = format!(
            "#!/bin/bash\n#SBATCH --job-name={name}\n#SBATCH --output=\"{}/{log}\"\n#SBATCH --cpus-per-task={}\n",
            sbatch_path(self.logs),
            self.cpus
        );
        if let Some(p) = self.partition {
            h += &format!("#SBATCH --partition={p}\n");
        }
        if let Some(t) = self.time {
            h += &format!("#SBATCH --time={t}\n");
        }
        h
    }

    fn common(&self) -> String {
        format!(
            "set -euo pipefail\ncd {}\nexport RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{}}}\"\n",
            quote(self.workdir),
            self.cpus
        )
    }

    fn locations(&self) -> String {
        format!(
            "--pipeline {} --results {}",
            quote(self.pipeline),
            quote(self.results)
        )
    }

    /// The array job: task I computes shard I/N.
    pub fn array_script(&self) -> String {
        self.script(
            ("", "%A_%a"),
            &format!("#SBATCH --array=0-{}\n", self.tasks.saturating_sub(1)),
            &format!(
                "Shard I of {} of sweep `{}`; re-running a task skips its finished points.",
                self.tasks, self.stage
            ),
            &format!(
                "run {} --shard \"${{SLURM_ARRAY_TASK_ID}}/{}\"",
                self.stage, self.tasks
            ),
        )
    }

    /// The merge job (submitted with `--dependency=afterok:<array job id>`).
    pub fn merge_script(&self) -> String {
        self.script(
            ("-merge", "merge-%j"),
            "",
            &format!(
                "Joins the {} parts of `{}` into its result; refuses an incomplete set.",
                self.tasks, self.stage
            ),
            &format!("merge {}", self.stage),
        )
    }

    /// A job script: named `woodpile-STAGE{suffix}`, logging to `STAGE-{log}.out`, with the
    /// extra `#SBATCH` lines `directives`, a `comment`, and `woodpile {command}` as its work.
    fn script(
        &self,
        (suffix, log): (&str, &str),
        directives: &str,
        comment: &str,
        command: &str,
    ) -> String {
        let mut s = self.header(
            &format!("woodpile-{}{suffix}", self.stage),
            &format!("{}-{log}.out", self.stage),
        );
        s += directives;
        s += &format!("# {comment}\n");
        s += &self.common();
        s += &format!(
            "exec {} {command} {}\n",
            quote(self.binary),
            self.locations()
        );
        s
    }

    /// Submits both, chained: prints the two job ids. `sbatch_flags` (e.g. `--wait`) go to the
    /// merge job's submission.
    pub fn submit_script(&self, array: &Path, merge: &Path) -> String {
        format!(
            "#!/bin/bash\n# Submit the `{stage}` array, then its merge job once every task succeeded.\n\
             # Extra arguments (e.g. --wait) are passed to the merge job's sbatch.\n\
             set -euo pipefail\nmkdir -p {logs}\n\
             array=$(sbatch --parsable {array})\n\
             merge=$(sbatch --parsable --dependency=afterok:\"${{array%%;*}}\" \"$@\" {merge})\n\
             echo \"array job $array, merge job $merge\"\n",
            stage = self.stage,
            logs = quote(self.logs),
            array = quote(array),
            merge = quote(merge),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A job as the CLI would make it, with `logs` as `--out`.
    fn job_with(cpus: usize, logs: &Path) -> SlurmJob<'_> {
        SlurmJob {
            stage: "f7_coarse",
            tasks: 2,
            partition: None,
            time: None,
            cpus,
            binary: Path::new("/opt/wp/woodpile"),
            workdir: Path::new("/home/me/woodpile"),
            pipeline: Path::new("pipeline"),
            results: Path::new("results"),
            logs,
        }
    }

    /// What sbatch would misread is refused or escaped: an absurd CPU count, a `%` in the log
    /// folder (sbatch's job-number patterns), spaces (its line splitting), quotes.
    #[test]
    fn cpus_are_bounded_and_the_output_path_is_quoted_and_escaped() {
        let logs = Path::new("/home/me/my logs/100%j");
        assert!(job_with(usize::MAX, logs)
            .validate()
            .unwrap_err()
            .contains("--cpus"));
        assert!(job_with(0, logs).validate().is_err());
        let job = job_with(4, logs);
        job.validate().unwrap();
        assert!(job
            .array_script()
            .contains("#SBATCH --output=\"/home/me/my logs/100%%j/f7_coarse-%A_%a.out\"\n"));
        let quoted = Path::new("/tmp/a\"b");
        assert!(job_with(4, quoted)
            .validate()
            .unwrap_err()
            .contains("--out"));
    }

    #[test]
    fn scripts_shard_by_array_index_and_chain_the_merge() {
        let job = SlurmJob {
            stage: "f7_coarse",
            tasks: 16,
            partition: Some("short"),
            time: Some("00:30:00"),
            cpus: 4,
            binary: Path::new("/opt/wp/woodpile"),
            workdir: Path::new("/home/me/woodpile"),
            pipeline: Path::new("pipeline"),
            results: Path::new("results"),
            logs: Path::new("/home/me/woodpile/slurm/logs"),
        };
        let array = job.array_script();
        assert!(array.contains("#SBATCH --array=0-15\n"));
        assert!(array.contains("#SBATCH --partition=short\n#SBATCH --time=00:30:00\n"));
        assert!(array.contains("run f7_coarse --shard \"${SLURM_ARRAY_TASK_ID}/16\""));
        let merge = job.merge_script();
        assert!(merge.contains("merge f7_coarse --pipeline 'pipeline' --results 'results'"));
        let submit = job.submit_script(Path::new("a.sbatch"), Path::new("m.sbatch"));
        assert!(submit.contains("--dependency=afterok:"));
    }
}
