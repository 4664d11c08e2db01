-- granflow results database, schema version 1.
--
-- One SQLite file per campaign directory (results/<campaign>/campaign.sqlite). The dispatcher is its only writer;
-- `granflow query` and friends read it through a read-only connection while campaigns run (WAL mode).
--
-- This file is migration 1, applied by src/store/migrations.rs inside one transaction that also sets
-- `PRAGMA user_version = 1`. It must therefore contain no BEGIN/COMMIT and no PRAGMA. Never edit it once released:
-- a schema change is a new migration (a new file appended to MIGRATIONS), which bumps the version.
--
-- Conventions:
--   * Timestamps are unix seconds (REAL, UTC, sub-second precision), e.g. started_at = 1767225600.25.
--   * Quantities are SI with the unit in the column name (sim_time_s) or in a `unit` column (metrics, derived);
--     unit '' means dimensionless.
--   * Metric values are NULL when the reducer produced NaN (SQLite itself stores a bound NaN as NULL); ±inf is
--     stored as is.
--   * CHOICE: plain (not STRICT) tables, so that the sqlite3 shells and Python builds found on clusters (older than
--     SQLite 3.37) can still open the file; the code binds typed values, CHECK constraints guard the enumerations.

-- A campaign: the campaign file as it was run, so that `resume` re-derives the job set from what was stored.
CREATE TABLE campaigns (
    id             INTEGER PRIMARY KEY,
    name           TEXT    NOT NULL UNIQUE,
    spec_yaml      TEXT    NOT NULL,        -- the campaign file, verbatim
    spec_hash      TEXT    NOT NULL,        -- hash of the canonical resolved spec; a change means new job ids
    created_at     REAL    NOT NULL,        -- unix seconds of the first run; kept by later upserts
    engine_version TEXT    NOT NULL         -- granflow version of the latest run
);

-- One row per job of the sweep. job_id is the hash of the job's canonical resolved parameters, so it is stable
-- across resumes and never renumbered.
CREATE TABLE jobs (
    job_id         TEXT    PRIMARY KEY,
    campaign_id    INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
    ordinal        INTEGER NOT NULL,        -- position in the sweep (display order, Slurm array index)
    params_json    TEXT    NOT NULL,        -- the resolved parameters as JSON (the `params` table is for WHERE)
    status         TEXT    NOT NULL DEFAULT 'pending'
                           CHECK (status IN ('pending', 'running', 'done', 'failed')),
    attempt        INTEGER NOT NULL DEFAULT 0 CHECK (attempt >= 0), -- current or last attempt; 0 = never started
    exit_class     TEXT,                    -- failure class of the last failed attempt; NULL unless it failed
    error          TEXT,                    -- message of the last failed attempt
    host           TEXT,                    -- host of the current or last attempt
    started_at     REAL,                    -- start of the current or last attempt
    finished_at    REAL,                    -- set when status becomes 'done' or 'failed'
    last_heartbeat REAL,                    -- last progress report of a running job (stale = lost worker)
    sim_time_s     REAL,                    -- simulated time reached (progress while running, final when done)
    wall_time_s    REAL,                    -- wall-clock time of the successful attempt
    steps          INTEGER CHECK (steps >= 0) -- time steps taken (progress while running, final when done)
);
CREATE INDEX jobs_by_campaign_status  ON jobs (campaign_id, status);   -- status counts, done ids, resume
CREATE INDEX jobs_by_campaign_ordinal ON jobs (campaign_id, ordinal);  -- summaries and exports in sweep order

-- History of every attempt of every job: one row per start (a preempted job restarted with the same attempt
-- number gets a second row), plus a row for failures recorded without a start.
CREATE TABLE attempts (
    id          INTEGER PRIMARY KEY,
    job_id      TEXT    NOT NULL REFERENCES jobs(job_id) ON DELETE CASCADE,
    attempt     INTEGER NOT NULL CHECK (attempt >= 0),
    host        TEXT,
    outcome     TEXT    NOT NULL DEFAULT 'running'
                        -- 'requeued': failed, job put back to pending for a retry; 'interrupted': the dispatcher
                        -- stopped while it ran and its end was not observed (see reset_running_to_pending)
                        CHECK (outcome IN ('running', 'done', 'failed', 'requeued', 'interrupted')),
    exit_class  TEXT,                       -- failure class; NULL unless outcome is 'failed' or 'requeued'
    error       TEXT,
    started_at  REAL,
    ended_at    REAL                        -- NULL while running or when interrupted
);
CREATE INDEX attempts_by_job ON attempts (job_id, attempt);

-- The resolved parameters of each job, one row per parameter, for WHERE clauses and pivots. Exactly one of
-- value_real (numbers, including integers) and value_text (names, booleans, ...) is set.
CREATE TABLE params (
    job_id     TEXT NOT NULL REFERENCES jobs(job_id) ON DELETE CASCADE,
    name       TEXT NOT NULL,               -- dotted path in the campaign file, with unit suffix (gas.u_m_per_s)
    value_real REAL,
    value_text TEXT,
    PRIMARY KEY (job_id, name),
    CHECK ((value_real IS NULL) <> (value_text IS NULL))
);
CREATE INDEX params_by_name_real ON params (name, value_real);  -- WHERE name = ? AND value_real BETWEEN ...
CREATE INDEX params_by_name_text ON params (name, value_text);  -- WHERE name = ? AND value_text = ...

-- The reduced metrics of a finished job (result.json). Re-ingesting a result replaces its rows.
CREATE TABLE metrics (
    job_id TEXT NOT NULL REFERENCES jobs(job_id) ON DELETE CASCADE,
    name   TEXT NOT NULL,
    value  REAL,                            -- NULL when the reducer produced NaN
    unit   TEXT NOT NULL,                   -- SI unit, '' for dimensionless
    PRIMARY KEY (job_id, name)
);
CREATE INDEX metrics_by_name ON metrics (name);  -- "all values of metric X" across jobs

-- Campaign-level metrics computed from several jobs (u_mf from a velocity sweep, phase classification). group_json
-- is the canonical JSON of the parameters that identify the group of jobs ('{}' for the whole campaign).
CREATE TABLE derived (
    campaign_id INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
    group_json  TEXT    NOT NULL,
    name        TEXT    NOT NULL,
    value       REAL,                       -- NULL when the reducer produced NaN
    unit        TEXT    NOT NULL,
    PRIMARY KEY (campaign_id, group_json, name)
);

-- Wall-clock seconds per engine stage of a finished job (neighbour search, forces, gas, checkpoint, ...).
CREATE TABLE timings (
    job_id  TEXT NOT NULL REFERENCES jobs(job_id) ON DELETE CASCADE,
    stage   TEXT NOT NULL,
    seconds REAL NOT NULL CHECK (seconds >= 0),
    PRIMARY KEY (job_id, stage)
);
