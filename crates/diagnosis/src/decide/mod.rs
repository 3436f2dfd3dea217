//! Stage 5, the decision: rounds of localization and addition, named effects and the signatures
//! that earn their names, discovered terms, alternatives, compounds, elimination and withdrawal.

pub mod additions;
pub(crate) mod alternatives;
pub(crate) mod beside;
pub(crate) mod decision;
pub(crate) mod discover;
pub(crate) mod eliminate;
pub(crate) mod findings;
pub(crate) mod flexible;
pub(crate) mod frequency;
pub(crate) mod joint_refit;
pub(crate) mod named;
pub(crate) mod named_effect;
pub(crate) mod named_instead;
pub(crate) mod named_places;
pub(crate) mod named_rivals;
pub(crate) mod new_term;
pub(crate) mod pairs;
pub(crate) mod revisit;
pub(crate) mod rounds;
pub(crate) mod withdraw;
