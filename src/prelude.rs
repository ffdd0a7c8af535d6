//! Everything a program that loads a model and simulates it needs, in one import:
//! `use lagrange::prelude::*;`.
//!
//! ```
//! use lagrange::prelude::*;
//! let model = Model::from_str(r#"<mujoco><worldbody><body><freejoint/><geom size="0.1"/></body>
//!     </worldbody></mujoco>"#)?;
//! let mut data = Data::new(&model);
//! step(&model, &mut data)?;
//! assert!(data.qvel[2] < 0.0); // falling
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::constraint::contact_force::{contact_force, contacts, ContactInfo};
pub use crate::constraint::ConstraintMode;
pub use crate::error::InputError;
pub use crate::forward::forward;
pub use crate::frames;
pub use crate::integrate::{step, IntegratorKind, StepReport};
pub use crate::io::{LoadError, LoadOptions};
pub use crate::model::reset::{reset, reset_keyframe};
pub use crate::model::{Data, Model};
pub use crate::sim::{SimError, SimOptions, Simulation};
