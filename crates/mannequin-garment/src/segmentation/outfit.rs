//! Which garments the person wears, decided from what the clip showed (`--garments auto`) or
//! named by the user, and the label legend that follows from it.

use serde::Serialize;

use super::class::Class;
use crate::category::Category;
use crate::ngd::NgdError;
use crate::ngd::layers::parse_item;

/// Above this overlap of their colour distributions, the upper and lower garment are one dress.
pub const DRESS_OVERLAP: f64 = 0.55;
/// Above this share of the forearms showing the upper garment, its sleeves are long.
pub const LONG_SLEEVE: f64 = 0.5;
/// Above this share of the shins showing the lower garment, it reaches the ankles.
pub const FULL_LENGTH: f64 = 0.5;
/// Above this share of the rows across both thighs showing the lower garment as one unbroken
/// run, a lower garment that leaves the shins bare hangs free between the legs: a skirt, not
/// shorts.
pub const SKIRT_SPAN: f64 = 0.5;
/// A lower garment that covers the shins is a long skirt only where it joins the legs in nearly
/// every row: trousers, loose or seen at low resolution, join them in up to 0.83 (measured).
pub const LONG_SKIRT_SPAN: f64 = 0.95;

/// What the clip showed that the decision reads.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Evidence {
    /// Bhattacharyya coefficient of the upper and lower garments' colours.
    pub colour_overlap: f64,
    /// Share of the forearms' votes for the upper garment (against skin).
    pub forearms_covered: f64,
    /// Share of the shins' votes for the lower garment (against skin).
    pub shins_covered: f64,
    /// Share of the rows across both thighs (where the body's thighs are apart) in which the
    /// lower garment is one unbroken run.
    pub legs_joined: f64,
}

/// The garments worn: a dress alone, or a top over a lower garment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outfit {
    Dress,
    TwoPiece { upper: Category, lower: Category },
}

/// The body labels every legend starts with.
pub const BODY_LABELS: [&str; 4] = ["background", "skin", "hair", "shoes"];

impl Outfit {
    /// The outfit `spec` names (`auto` decides it from `evidence`), and whether it was decided.
    pub fn choose(spec: &str, evidence: &Evidence) -> Result<(Self, bool), NgdError> {
        if spec == "auto" { Ok((Self::decide(evidence), true)) } else { Ok((Self::named(spec)?, false)) }
    }

    /// The outfit a `--garments` value other than `auto` names: a dress alone, or one upper and
    /// one lower garment.
    pub fn named(spec: &str) -> Result<Self, NgdError> {
        let named: Vec<Category> = spec.split(',').map(|i| parse_item(i.trim())).collect::<Result<_, _>>()?;
        match named.as_slice() {
            [Category::Dress] => Ok(Outfit::Dress),
            [a, b] if a.is_lower_body() != b.is_lower_body() && !named.contains(&Category::Dress) => {
                let (upper, lower) = if a.is_lower_body() { (*b, *a) } else { (*a, *b) };
                Ok(Outfit::TwoPiece { upper, lower })
            }
            _ => Err(NgdError::flag(
                "--garments",
                format!(
                    "'{spec}': name a dress alone, or one upper and one lower garment (upper:tshirt,lower:pants), or auto"
                ),
            )),
        }
    }

    /// `auto`: one dress where the two garments' colours are alike and the lower part spans the
    /// legs (a suit is alike too, but has trouser legs); otherwise the sleeves' and legs'
    /// lengths, and whether the lower garment spans the legs, name the categories.
    pub fn decide(e: &Evidence) -> Self {
        if e.colour_overlap > DRESS_OVERLAP && e.legs_joined > SKIRT_SPAN {
            return Outfit::Dress;
        }
        let upper = if e.forearms_covered > LONG_SLEEVE { Category::Shirt } else { Category::Tshirt };
        let lower = match (e.shins_covered > FULL_LENGTH, e.legs_joined) {
            (true, joined) if joined > LONG_SKIRT_SPAN => Category::Skirt,
            (true, _) => Category::Pants,
            (false, joined) if joined > SKIRT_SPAN => Category::Skirt,
            (false, _) => Category::ShortPants,
        };
        Outfit::TwoPiece { upper, lower }
    }

    /// The label names by index: the body's, then the lower garment, then the upper (a dress is
    /// one label).
    pub fn legend(self) -> Vec<String> {
        let mut legend: Vec<String> = BODY_LABELS.iter().map(|s| s.to_string()).collect();
        match self {
            Outfit::Dress => legend.push(Category::Dress.name().into()),
            Outfit::TwoPiece { upper, lower } => {
                legend.push(lower.name().into());
                legend.push(upper.name().into());
            }
        }
        legend
    }

    /// The label index of a class in [`Outfit::legend`].
    pub fn label(self, class: Class) -> u8 {
        match (class, self) {
            (Class::Skin, _) => 1,
            (Class::Hair, _) => 2,
            (Class::Shoes, _) => 3,
            (Class::Upper | Class::Lower, Outfit::Dress) | (Class::Lower, Outfit::TwoPiece { .. }) => 4,
            (Class::Upper, Outfit::TwoPiece { .. }) => 5,
        }
    }

    pub fn categories(self) -> Vec<Category> {
        match self {
            Outfit::Dress => vec![Category::Dress],
            Outfit::TwoPiece { upper, lower } => vec![lower, upper],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn evidence(colour_overlap: f64, forearms: f64, shins: f64, off: f64) -> Evidence {
        Evidence { colour_overlap, forearms_covered: forearms, shins_covered: shins, legs_joined: off }
    }

    #[test]
    fn auto_reads_sleeves_legs_and_the_span_between_the_legs() {
        assert_eq!(Outfit::decide(&evidence(0.9, 0.0, 0.0, 0.9)), Outfit::Dress);
        // A suit: alike colours, trouser legs.
        let o = Outfit::decide(&evidence(0.9, 0.9, 0.9, 0.2));
        assert_eq!(o, Outfit::TwoPiece { upper: Category::Shirt, lower: Category::Pants });
        let o = Outfit::decide(&evidence(0.1, 0.1, 0.9, 0.8));
        assert_eq!(o, Outfit::TwoPiece { upper: Category::Tshirt, lower: Category::Pants });
        let o = Outfit::decide(&evidence(0.1, 0.1, 0.9, 0.99));
        assert_eq!(o, Outfit::TwoPiece { upper: Category::Tshirt, lower: Category::Skirt });
        let o = Outfit::decide(&evidence(0.1, 0.8, 0.1, 0.8));
        assert_eq!(o, Outfit::TwoPiece { upper: Category::Shirt, lower: Category::Skirt });
        let o = Outfit::decide(&evidence(0.1, 0.1, 0.1, 0.0));
        assert_eq!(o, Outfit::TwoPiece { upper: Category::Tshirt, lower: Category::ShortPants });
    }

    #[test]
    fn a_named_outfit_is_a_dress_or_one_top_and_one_bottom() {
        let e = evidence(0.0, 0.0, 0.0, 0.0);
        let (o, decided) = Outfit::choose("lower:pants,upper:tshirt", &e).unwrap();
        assert!(!decided);
        assert_eq!(o.legend(), ["background", "skin", "hair", "shoes", "pants", "tshirt"]);
        assert_eq!(o.label(Class::Upper), 5);
        assert_eq!(Outfit::choose("dress", &e).unwrap().0.label(Class::Lower), 4);
        for bad in ["tshirt", "pants,skirt", "dress,pants", "upper:cape,lower:pants"] {
            let err = Outfit::choose(bad, &e).unwrap_err().to_string();
            assert!(err.starts_with("--garments: "), "{bad}: {err}");
        }
    }
}
