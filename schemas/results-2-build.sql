-- granflow results database, migration 2: which build ran each attempt, and which campaign file the user ran.
--
-- Applied by src/store/migrations.rs after migration 1 (schemas/results.sql), in the same kind of transaction; no
-- BEGIN/COMMIT, no PRAGMA. Never edit it once released.

-- The granflow build that ran the attempt (src/provenance.rs: version + git commit, `.dirty` when its sources
-- differed from the commit): set when the attempt starts, and when a job finishes to the build that wrote its
-- result.json. NULL for attempts recorded before this migration.
ALTER TABLE attempts ADD COLUMN build TEXT;

-- The campaign file as the user named it at the latest `granflow run` (relative to where it was run), for the
-- "Reproduce" command of `granflow report`; `resume` keeps it. NULL for campaigns run before this migration.
ALTER TABLE campaigns ADD COLUMN source_path TEXT;
