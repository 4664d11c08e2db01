-- granflow results database, migration 3: the Slurm array task that runs a job.
--
-- Applied by src/store/migrations.rs after migration 2, in the same kind of transaction; no BEGIN/COMMIT, no PRAGMA.
-- Never edit it once released.

-- The Slurm array task of the job's current or last submission (`<array job id>_<index>`), set when the dispatcher
-- submits it and kept after it ends; NULL for jobs run by the local executor. A `running` job with a task is in
-- Slurm's hands: a dispatcher that starts again asks `squeue` about it instead of putting it back to `pending`.
ALTER TABLE jobs ADD COLUMN slurm_task TEXT;
-- The task's state as `squeue` last reported it (PENDING, RUNNING, …; `ENDED` once it left the queue).
ALTER TABLE jobs ADD COLUMN slurm_state TEXT;
