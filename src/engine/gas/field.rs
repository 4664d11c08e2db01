//! The gas state's fields by name and unit: one table ([`GasField`]) of the fields every gas carries (pressure,
//! the three face velocity components, porosity), and views ([`GasFieldView`]) that list them with the
//! transported scalars a simulation declares (each brings its own name and unit,
//! [`super::transported_scalar::GasScalarSpec`]). Code that needs every field — non-finite checks, restore shape
//! checks, state comparison — walks these views instead of naming fields one by one. The names are those of the
//! checkpoint's `gas/` datasets. The particle-exchange sums are not fields of the state; they live with
//! [`super::exchange_accumulator::ExchangeAccumulator`].

use super::grid::Grid;
use super::simple::GasState;

/// Where a field's values live on the staggered grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldLocation {
    /// One value per cell centre.
    Cells,
    /// One value per face normal to `axis` (a velocity component).
    Faces { axis: usize },
}

impl FieldLocation {
    /// How many values a field at this location has on `grid`.
    pub fn len(self, grid: &Grid) -> usize {
        match self {
            FieldLocation::Cells => grid.cells(),
            FieldLocation::Faces { axis } => grid.faces(axis),
        }
    }
}

/// The fields every gas state carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GasField {
    Pressure,
    VelocityX,
    VelocityY,
    VelocityZ,
    Porosity,
}

impl GasField {
    /// Every field, in the order views list them.
    pub const ALL: [GasField; 5] = [
        GasField::Pressure,
        GasField::VelocityX,
        GasField::VelocityY,
        GasField::VelocityZ,
        GasField::Porosity,
    ];

    /// The field's name, with its unit suffix (the checkpoint dataset's name under `gas/`).
    pub const fn name(self) -> &'static str {
        match self {
            GasField::Pressure => "pressure_pa",
            GasField::VelocityX => "velocity_x_m_per_s",
            GasField::VelocityY => "velocity_y_m_per_s",
            GasField::VelocityZ => "velocity_z_m_per_s",
            GasField::Porosity => "porosity",
        }
    }

    pub const fn unit(self) -> &'static str {
        match self {
            GasField::Pressure => "Pa",
            GasField::VelocityX | GasField::VelocityY | GasField::VelocityZ => "m/s",
            GasField::Porosity => "1",
        }
    }

    /// What the field is.
    pub const fn doc(self) -> &'static str {
        match self {
            GasField::Pressure => {
                "gas pressure at cell centres, relative to the outlet (or to its mean without an outlet)"
            }
            GasField::VelocityX => "gas velocity along x on the x faces (superficial where gas enters from a plenum)",
            GasField::VelocityY => "gas velocity along y on the y faces (superficial where gas enters from a plenum)",
            GasField::VelocityZ => "gas velocity along z on the z faces (zero on a 2-D grid)",
            GasField::Porosity => "gas volume fraction ε at cell centres",
        }
    }

    pub const fn location(self) -> FieldLocation {
        match self {
            GasField::Pressure | GasField::Porosity => FieldLocation::Cells,
            GasField::VelocityX => FieldLocation::Faces { axis: 0 },
            GasField::VelocityY => FieldLocation::Faces { axis: 1 },
            GasField::VelocityZ => FieldLocation::Faces { axis: 2 },
        }
    }

    /// This field's values among a state's arrays.
    pub(crate) fn select<'a>(
        self,
        pressure_pa: &'a [f64],
        velocity_m_per_s: &'a [Vec<f64>; 3],
        porosity: &'a [f64],
    ) -> &'a [f64] {
        match self {
            GasField::Pressure => pressure_pa,
            GasField::VelocityX => &velocity_m_per_s[0],
            GasField::VelocityY => &velocity_m_per_s[1],
            GasField::VelocityZ => &velocity_m_per_s[2],
            GasField::Porosity => porosity,
        }
    }

    /// The view of this field among a state's arrays.
    pub(crate) fn view<'a>(
        self,
        pressure_pa: &'a [f64],
        velocity_m_per_s: &'a [Vec<f64>; 3],
        porosity: &'a [f64],
    ) -> GasFieldView<'a> {
        GasFieldView {
            name: self.name(),
            unit: self.unit(),
            location: self.location(),
            values: self.select(pressure_pa, velocity_m_per_s, porosity),
        }
    }
}

/// One field's values with its name and unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GasFieldView<'a> {
    pub name: &'a str,
    pub unit: &'a str,
    pub location: FieldLocation,
    pub values: &'a [f64],
}

impl GasState {
    /// The fields of [`GasField::ALL`], in that order.
    pub fn fields(&self) -> impl Iterator<Item = GasFieldView<'_>> {
        GasField::ALL
            .into_iter()
            .map(|f| f.view(&self.pressure_pa, &self.velocity_m_per_s, &self.porosity))
    }
}

#[cfg(test)]
mod tests {
    use super::{FieldLocation, GasField};
    use crate::engine::gas::grid::{Boundary, Grid};
    use crate::engine::gas::simple::GasState;

    fn grid() -> Grid {
        Grid {
            n: [3, 2, 1],
            h_m: [0.1; 3],
            origin_m: [0.0; 3],
            boundary: [Boundary::Outlet; 6],
        }
    }

    #[test]
    fn every_field_has_a_unique_name_with_its_unit_suffix_and_the_shape_of_its_location() {
        let grid = grid();
        let state = GasState::new(&grid);
        let views: Vec<_> = state.fields().collect();
        assert_eq!(views.len(), GasField::ALL.len());
        for (field, view) in GasField::ALL.iter().zip(&views) {
            assert_eq!(view.name, field.name());
            assert_eq!(view.values.len(), view.location.len(&grid), "{}", view.name);
            assert!(!field.doc().is_empty());
            let suffix = match view.unit {
                "Pa" => "_pa",
                "m/s" => "_m_per_s",
                "1" => "",
                other => panic!("{}: unit {other} has no suffix rule", view.name),
            };
            assert!(view.name.ends_with(suffix), "{} does not end with {suffix}", view.name);
            assert_eq!(views.iter().filter(|v| v.name == view.name).count(), 1);
        }
        assert_eq!(GasField::VelocityY.location(), FieldLocation::Faces { axis: 1 });
    }
}
