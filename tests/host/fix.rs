//! The `--fix` predicates (`palpate::fix`): parsing every operator, refusing bad text.

use palpate::fix::FixPredicate;

#[test]
fn parses_all_operators() {
    let p: FixPredicate = "z<0.001".parse().unwrap();
    assert!(p.matches(&[5.0, 5.0, 0.0]) && !p.matches(&[0.0, 0.0, 0.001]));
    let p: FixPredicate = "x>=1".parse().unwrap();
    assert!(p.matches(&[1.0, 0.0, 0.0]) && !p.matches(&[0.999, 0.0, 0.0]));
    let p: FixPredicate = "y<=-2.5".parse().unwrap();
    assert!(p.matches(&[0.0, -2.5, 0.0]) && !p.matches(&[0.0, -2.4, 0.0]));
    let p: FixPredicate = "y>2".parse().unwrap();
    assert!(!p.matches(&[0.0, 2.0, 0.0]) && p.matches(&[0.0, 2.1, 0.0]));
}

#[test]
fn rejects_bad_predicates() {
    for bad in ["", "w<1", "z", "z=1", "z<", "z<abc", "z<nan", "z<inf", "<1"] {
        assert!(bad.parse::<FixPredicate>().is_err(), "{bad}");
    }
}
