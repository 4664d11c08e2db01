//! Per-particle scalar channels: what the pair pass carries besides force and torque, declared once.
//!
//! A channel is one `f64` per particle that the pair pass adds into, contact by contact, in the same fixed order as
//! the forces (so any thread count gives the same bits). Each contact kernel returns its contributions as a
//! [`ScalarFlows`] (the amount for particle i; particle j receives it with the channel's [`Partner`] rule: a flow
//! such as heat leaves j as it enters i, a count is counted on both). The [`scalar_channels!`] declaration below is
//! the only list of channels; it generates the per-contact [`ScalarFlows`], the per-particle store
//! [`ParticleChannels`] (empty columns when the run does not ask for channels, so a run that does not pays
//! nothing), its views for the parallel pass, and [`CHANNELS`], the table that the checkpoint's datasets, the restart
//! comparison and the reference digests are built from.
//!
//! Adding a channel is one line in the declaration plus the kernel that fills it. Each channel belongs to a
//! [`ChannelGroup`] that a run switches on as a whole: the contact statistics of `output.contact_statistics` (totals
//! over the run, part of the state and checkpointed) and heat (the conduction into each particle during one step,
//! consumed by the particle's temperature update in the same pass and so zero between steps).

/// How particle j of a pair receives what a kernel gives particle i.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Partner {
    /// j receives the same amount (a count, a duration).
    Same,
    /// j receives the opposite amount (a flow from j to i: heat, liquid).
    Opposite,
}

/// The groups of channels a run switches on or off together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelGroup {
    /// Contact counts and durations (`output.contact_statistics`).
    Statistics,
    /// Heat flowing into each particle by conduction this step (a run with `heat`).
    Heat,
}

/// Which groups a run records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ChannelGroups {
    pub statistics: bool,
    pub heat: bool,
}

impl ChannelGroups {
    pub const NONE: ChannelGroups = ChannelGroups {
        statistics: false,
        heat: false,
    };

    pub fn has(&self, group: ChannelGroup) -> bool {
        match group {
            ChannelGroup::Statistics => self.statistics,
            ChannelGroup::Heat => self.heat,
        }
    }
}

/// One channel, for the generic walkers (checkpoint, restart comparison, digests).
#[derive(Debug, Clone, Copy)]
pub struct ChannelInfo {
    pub name: &'static str,
    pub group: ChannelGroup,
    pub unit: &'static str,
    pub doc: &'static str,
    pub partner: Partner,
    /// Its checkpoint dataset.
    pub path: &'static str,
    pub get: fn(&ParticleChannels) -> &Vec<f64>,
    pub get_mut: fn(&mut ParticleChannels) -> &mut Vec<f64>,
}

/// Declares the channels; see the module documentation for what it generates.
macro_rules! scalar_channels {
    ($( $(#[$doc:meta])* $name:ident: $unit:literal, $partner:ident, $group:ident, $text:literal; )*) => {
        /// One contact's contributions to every channel, for particle i.
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct ScalarFlows {
            $( $(#[$doc])* pub $name: f64, )*
        }

        impl ScalarFlows {
            pub const ZERO: ScalarFlows = ScalarFlows { $( $name: 0.0, )* };

            /// Adds another contact's flows.
            #[inline(always)]
            pub fn add(&mut self, other: &ScalarFlows) {
                $( self.$name += other.$name; )*
            }

            /// What particle j of the pair receives.
            #[inline(always)]
            pub fn for_partner(&self) -> ScalarFlows {
                ScalarFlows { $( $name: match Partner::$partner {
                    Partner::Same => self.$name,
                    Partner::Opposite => -self.$name,
                }, )* }
            }
        }

        /// Every channel's value per particle (a column is empty when the run does not record its group).
        #[derive(Debug, Clone, Default, PartialEq)]
        pub struct ParticleChannels {
            $( $(#[$doc])* pub $name: Vec<f64>, )*
        }

        /// A mutable view of a range of particles' channels (the parallel pass works on disjoint views).
        pub struct ChannelsMut<'a> {
            $( pub $name: &'a mut [f64], )*
        }

        impl ParticleChannels {
            /// Zeroed channels for `n` particles in the groups `on`, empty columns for the others.
            pub fn new(n: usize, on: ChannelGroups) -> Self {
                ParticleChannels { $( $name: vec![0.0; if on.has(ChannelGroup::$group) { n } else { 0 }], )* }
            }

            /// Which groups these channels record (a group is on when its columns are not empty; with no
            /// particles, none is).
            pub fn groups(&self) -> ChannelGroups {
                let mut on = ChannelGroups::NONE;
                $( if !self.$name.is_empty() {
                    match ChannelGroup::$group {
                        ChannelGroup::Statistics => on.statistics = true,
                        ChannelGroup::Heat => on.heat = true,
                    }
                } )*
                on
            }

            /// Whether the run records any channel.
            pub fn is_on(&self) -> bool {
                false $( || !self.$name.is_empty() )*
            }

            pub fn view(&mut self) -> ChannelsMut<'_> {
                ChannelsMut { $( $name: &mut self.$name, )* }
            }

            /// Disjoint views ending at the given particle offsets (empty views when off).
            pub fn split(&mut self, ends: &[usize]) -> Vec<ChannelsMut<'_>> {
                $( let mut $name = crate::engine::models::history::split_at_ends(&mut self.$name, ends).into_iter(); )*
                ends.iter()
                    .map(|_| ChannelsMut { $( $name: $name.next().expect("one piece per end"), )* })
                    .collect()
            }

            pub fn heap_bytes(&self) -> usize {
                0 $( + self.$name.capacity() * std::mem::size_of::<f64>() )*
            }

            /// The channels of the particles in a new order: particle k of the result is particle `order[k]` of
            /// these (`engine::particle_order`); columns that are off stay empty.
            pub fn permuted(&self, order: &[usize]) -> Self {
                ParticleChannels {
                    $( $name: if self.$name.is_empty() {
                        Vec::new()
                    } else {
                        order.iter().map(|&i| self.$name[i]).collect()
                    }, )*
                }
            }
        }

        impl ChannelsMut<'_> {
            /// A view of the same particles for a shorter borrow.
            pub fn reborrow(&mut self) -> ChannelsMut<'_> {
                ChannelsMut { $( $name: self.$name, )* }
            }

            /// Adds `flows` to particle i (local to the view), in the columns the run records (the test is the
            /// bounds check indexing would make anyway).
            #[inline(always)]
            pub fn add(&mut self, i: usize, flows: &ScalarFlows) {
                $( if let Some(value) = self.$name.get_mut(i) {
                    *value += flows.$name;
                } )*
            }
        }

        /// Every channel, in declaration order (the checkpoint's dataset order).
        pub const CHANNELS: &[ChannelInfo] = &[$(
            ChannelInfo {
                name: stringify!($name),
                group: ChannelGroup::$group,
                unit: $unit,
                doc: $text,
                partner: Partner::$partner,
                path: concat!("particles/channels/", stringify!($name)),
                get: |c: &ParticleChannels| &c.$name,
                get_mut: |c: &mut ParticleChannels| &mut c.$name,
            },
        )*];
    };
}

scalar_channels! {
    /// Particle–particle contacts of this particle that have ended (each counted on both particles).
    contacts_ended: "1", Same, Statistics, "particle-particle contacts ended (counted on both particles)";
    /// Their summed durations, s (the contact slot's `duration_s` when the contact ended).
    contact_time_ended_s: "s", Same, Statistics, "summed duration of the ended particle-particle contacts";
    /// Wall contacts of this particle that have ended.
    wall_contacts_ended: "1", Same, Statistics, "wall contacts ended";
    /// Their summed durations, s.
    wall_contact_time_ended_s: "s", Same, Statistics, "summed duration of the ended wall contacts";
    /// Time this particle has spent touching at least one wall, s.
    wall_contact_time_s: "s", Same, Statistics, "time spent touching at least one wall";
    /// Heat flowing into this particle by conduction (contacts, walls, liquid bridges) during the current step, W:
    /// summed by the pass and consumed by the particle's temperature update, so zero between steps.
    heat_flow_w: "W", Opposite, Heat, "heat flowing in by conduction during the current step (zero between steps)";
}

/// Sum of `values` in index order.
fn total(values: &[f64]) -> f64 {
    values.iter().sum()
}

impl ParticleChannels {
    /// Mean duration of the particle–particle contacts that ended, s (NaN when none did or the run records no
    /// channels). Each contact is counted on both its particles, which the ratio cancels.
    pub fn mean_collision_duration_s(&self) -> f64 {
        total(&self.contact_time_ended_s) / total(&self.contacts_ended)
    }

    /// Mean duration of the wall contacts that ended, s (NaN when none did).
    pub fn mean_wall_contact_duration_s(&self) -> f64 {
        total(&self.wall_contact_time_ended_s) / total(&self.wall_contacts_ended)
    }

    /// The fraction of `elapsed_s` (the run's time since its start, when the channels were zero) a particle spent
    /// touching a wall, mean over the particles (NaN without particles or channels).
    pub fn wall_contact_time_fraction(&self, elapsed_s: f64) -> f64 {
        total(&self.wall_contact_time_s) / (self.wall_contact_time_s.len() as f64 * elapsed_s)
    }
}
