//! `series.h5`: a job's time series, one 1-D dataset per column with a `units` attribute, written through a
//! temporary file and a rename.

use std::path::Path;

use hdf5::types::VarLenUnicode;

use super::reduce::Series;
use crate::error::Error;

pub fn write(path: &Path, series: &Series) -> Result<(), Error> {
    let tmp = path.with_extension("h5.tmp");
    let fail = |what: &str, e: hdf5::Error| Error::External(format!("write {} ({what}): {e}", tmp.display()));
    {
        let file = hdf5::File::create(&tmp).map_err(|e| fail("create", e))?;
        let format: VarLenUnicode = "granflow-series".parse().expect("ASCII");
        file.new_attr::<VarLenUnicode>()
            .create("format")
            .and_then(|a| a.write_scalar(&format))
            .map_err(|e| fail("format attribute", e))?;
        for (name, column) in series.names.iter().zip(&series.columns) {
            let ds = file
                .new_dataset_builder()
                .with_data(column.as_slice())
                .create(name.as_str())
                .map_err(|e| fail(name, e))?;
            let units: VarLenUnicode = Series::unit_of(name).parse().expect("ASCII");
            ds.new_attr::<VarLenUnicode>()
                .create("units")
                .and_then(|a| a.write_scalar(&units))
                .map_err(|e| fail(name, e))?;
        }
        file.flush().map_err(|e| fail("flush", e))?;
    }
    std::fs::rename(&tmp, path).map_err(|e| Error::io("rename", path, e))
}
