//! The macro behind the registry of back-ends in `select/mod.rs`: from one line per back-end
//! it writes the `Backend` enum of settings (serde-tagged by `method`, as model files write
//! it), the `BackendName` enum of the command line, and the name, lookup, check and build of
//! each, so a new back-end is its own file and one line of the registry.

macro_rules! back_ends {
    ($( $(#[$doc:meta])* $variant:ident($settings:ty) = $name:literal $(| $alias:literal)* ;)+) => {
        /// Back-end settings as written in model files and chosen on the CLI, by `method` name.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "method", rename_all = "kebab-case", deny_unknown_fields)]
        pub enum Backend {
            $( $(#[$doc])* $variant($settings), )+
        }

        /// A back-end by name, with its default settings (the command line's `--backend`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        #[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
        pub enum BackendName {
            $( $(#[$doc])* $(#[cfg_attr(feature = "cli", value(alias = $alias))])* $variant, )+
        }

        impl From<BackendName> for Backend {
            fn from(name: BackendName) -> Backend {
                match name {
                    $( BackendName::$variant => Backend::$variant(<$settings>::default()), )+
                }
            }
        }

        impl Backend {
            /// The names of all back-ends.
            pub const NAMES: &'static [&'static str] = &[$($name),+];

            /// The back-end's name (as in [`Backend::NAMES`]).
            pub fn name(&self) -> &'static str {
                match self {
                    $( Backend::$variant(_) => $name, )+
                }
            }

            /// A back-end with default settings, by name (or alias).
            pub fn by_name(name: &str) -> Result<Backend, SelectError> {
                match name {
                    $( $name $(| $alias)* => Ok(BackendName::$variant.into()), )+
                    other => Err(SelectError::Config(format!(
                        "unknown back-end `{other}` (known: {})",
                        Backend::NAMES.join(", ")
                    ))),
                }
            }

            /// Checks the settings (a model file's `backend` table is checked when it is read).
            /// Each back-end's `select` checks its own settings too, once per fit: a back-end
            /// used directly, without this enum, is checked all the same.
            pub fn validate(&self) -> Result<(), SelectError> {
                match self {
                    $( Backend::$variant(b) => b.validate(), )+
                }
            }

            /// The runnable back-end (its settings are checked when it selects).
            pub fn build(&self) -> Box<dyn Selector> {
                match self {
                    $( Backend::$variant(b) => Box::new(b.clone()), )+
                }
            }
        }
    };
}
