//! Enums whose values have a name (the study axis, the friction solver), each name written once.
//!
//! [`named_enum!`] declares the enum with its variants' names; from that one table it implements
//! `name()`, `Display`, `FromStr`, serde's `Serialize`/`Deserialize` (scene files, summaries) and
//! clap's `ValueEnum` (command-line options), so a name is spelled in one place.

/// `named_enum! { /// doc  pub enum Name { /// doc  Variant = "name", … } }`.
macro_rules! named_enum {
    ($(#[$m:meta])* pub enum $name:ident { $($(#[$vm:meta])* $var:ident = $s:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, PartialEq, Eq, Debug)]
        pub enum $name {
            $($(#[$vm])* $var),+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$var),+];

            /// The value's name (scene files, command line, reports).
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$var => $s),+
                }
            }

            /// "a, b or c": the names, for messages.
            pub fn expected() -> String {
                let names: Vec<&str> = Self::ALL.iter().map(|v| v.name()).collect();
                match names.split_last() {
                    Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
                    _ => names.join(""),
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.pad(self.name())
            }
        }

        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> std::result::Result<Self, String> {
                Self::ALL
                    .iter()
                    .copied()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| format!("`{s}`: expected {}", Self::expected()))
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                let s = String::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
            }
        }

        impl clap::ValueEnum for $name {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }
            fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
                Some(clap::builder::PossibleValue::new(self.name()))
            }
        }
    };
}
pub(crate) use named_enum;

#[cfg(test)]
mod tests {
    named_enum! {
        /// A test enum.
        pub enum Pick {
            /// First.
            One = "one",
            Two = "two",
            Three = "three",
        }
    }

    /// The system shall read, write and list a named enum's values by the names of its one table.
    #[test]
    fn names_round_trip() {
        for &v in Pick::ALL {
            assert_eq!(v.name().parse::<Pick>(), Ok(v));
            assert_eq!(v.to_string(), v.name());
        }
        assert_eq!(Pick::expected(), "one, two or three");
        assert_eq!("four".parse::<Pick>(), Err("`four`: expected one, two or three".to_string()));
        #[derive(serde::Deserialize)]
        struct T {
            p: Pick,
        }
        assert_eq!(toml::from_str::<T>("p = \"two\"").map(|t| t.p).ok(), Some(Pick::Two));
        let err = toml::from_str::<T>("p = \"zwei\"").err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err.contains("`zwei`: expected one, two or three"), "{err}");
        let names: Vec<String> = <Pick as clap::ValueEnum>::value_variants()
            .iter()
            .filter_map(|v| clap::ValueEnum::to_possible_value(v).map(|p| p.get_name().to_string()))
            .collect();
        assert_eq!(names, ["one", "two", "three"]);
    }
}
