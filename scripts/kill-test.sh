#!/usr/bin/env bash
# The worker kill test with more trials than CI runs: a campaign job is killed with SIGKILL at N random moments,
# resumed each time, and must end bit-identical (metrics, final state, time series) to an uninterrupted run.
#   scripts/kill-test.sh 100
set -euo pipefail
cd "$(dirname "$0")/.."
export GRANFLOW_KILL_TRIALS="${1:-100}"
cargo test --release --test campaign workers_killed_at_random_moments_resume_bit_identically -- --nocapture
