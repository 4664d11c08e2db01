//! Analysis: reducers that turn a job's particle states and time series into metrics.
