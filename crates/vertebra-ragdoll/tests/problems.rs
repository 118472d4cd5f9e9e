//! `check_toml` and `check_file` list every problem of a file, in file
//! order with their lines, and the single-error loaders refuse with the
//! first of them.

use vertebra_ragdoll::{RagdollDesc, RagdollError, Skeleton};

/// A ragdoll file with five independent problems: a NaN segment (body
/// `a`), an unknown bone (body `b`), a joint name used twice (`j`), a twist
/// limit with its ends swapped (joint `k`) and a hinge given a swing
/// (joint `m`, a table that cannot be read as its kind).
const SEVERAL: &str = "\
name = \"several\"

[[bone]]
name = \"root\"
translation = [0.0, 1.0, 0.0]

[[body]]
name = \"a\"
segment = [[0.0, 1.0, 0.0], [0.0, nan, 0.0]]
radius = 0.05
mass = 1.0

[[body]]
name = \"b\"
segment = [[0.0, 0.8, 0.0], [0.0, 0.7, 0.0]]
radius = 0.05
mass = 1.0
bone = \"nope\"

[[body]]
name = \"c\"
segment = [[0.0, 0.6, 0.0], [0.0, 0.5, 0.0]]
radius = 0.05
mass = 1.0

[[body]]
name = \"d\"
segment = [[0.0, 0.4, 0.0], [0.0, 0.3, 0.0]]
radius = 0.05
mass = 1.0

[[body]]
name = \"e\"
segment = [[0.0, 0.2, 0.0], [0.0, 0.1, 0.0]]
radius = 0.05
mass = 1.0

[[joint]]
name = \"j\"
parent = \"a\"
child = \"b\"
anchor = [0.0, 0.85, 0.0]
axis = [0.0, -1.0, 0.0]

[[joint]]
name = \"j\"
parent = \"b\"
child = \"c\"
anchor = [0.0, 0.65, 0.0]
axis = [0.0, -1.0, 0.0]

[[joint]]
name = \"k\"
parent = \"c\"
child = \"d\"
anchor = [0.0, 0.45, 0.0]
axis = [0.0, -1.0, 0.0]
twist = [50.0, 10.0]

[[joint]]
name = \"m\"
kind = \"hinge\"
parent = \"d\"
child = \"e\"
anchor = [0.0, 0.25, 0.0]
axis = [1.0, 0.0, 0.0]
swing = 30.0
";

/// The line (from 1) of the table whose `name = "..."` line is `name_line`
/// in `text`: the line before it.
fn table_line(text: &str, name_line: &str) -> usize {
    let at = text.find(name_line).expect("the name is in the text");
    text[..at].matches('\n').count()
}

#[test]
fn every_problem_of_a_ragdoll_file_is_listed_in_file_order() {
    let a = table_line(SEVERAL, "name = \"a\"");
    let b = table_line(SEVERAL, "name = \"b\"");
    let j2 = table_line(SEVERAL, "name = \"j\"\nparent = \"b\"");
    let k = table_line(SEVERAL, "name = \"k\"");
    let m = table_line(SEVERAL, "name = \"m\"");
    let problems: Vec<String> = RagdollDesc::check_toml(SEVERAL)
        .unwrap_err()
        .iter()
        .map(RagdollError::to_string)
        .collect();
    assert_eq!(
        problems,
        [
            format!("line {a}: body `a`: segment is not finite"),
            format!("line {b}: body `b`: bone `nope` is not a bone of the skeleton"),
            format!("line {j2}: joint name `j` is used twice"),
            format!("line {k}: joint `k`: twist must be [min, max] within [-180, 180] degrees"),
            format!("line {m}: joint `m`: swing is for sockets only; this joint is a hinge"),
        ]
    );
    // The single-error loader says the first.
    let first = RagdollDesc::check_toml(SEVERAL).unwrap_err().remove(0);
    assert_eq!(RagdollDesc::from_toml(SEVERAL).unwrap_err(), first);
}

/// A skeleton file with three bad bones among good ones.
const BAD_BONES: &str = "\
[[bone]]
name = \"root\"
translation = [0.0, 0.0, 0.0]

[[bone]]
name = \"hips\"
parent = \"pelvis\"
translation = [0.0, 1.0, 0.0]

[[bone]]
name = \"spine\"
parent = \"hips\"
translation = [0.0, nan, 0.0]

[[bone]]
name = \"root\"
translation = [0.0, 0.0, 0.0]

[[bone]]
name = \"head\"
parent = \"spine\"
translation = [0.0, 0.5, 0.0]
";

#[test]
fn every_bad_bone_of_a_skeleton_file_is_listed_in_file_order() {
    let problems: Vec<String> = Skeleton::check_toml(BAD_BONES)
        .unwrap_err()
        .iter()
        .map(RagdollError::to_string)
        .collect();
    assert_eq!(
        problems,
        [
            "line 5: bone `hips`: parent `pelvis` is not a bone of the skeleton",
            "line 10: bone `spine`: translation is not finite",
            "line 15: bone name `root` is used twice",
        ]
    );
    let first = Skeleton::check_toml(BAD_BONES).unwrap_err().remove(0);
    assert_eq!(Skeleton::from_toml(BAD_BONES).unwrap_err(), first);
}

/// A ragdoll file whose own `[[bone]]` tables are bad lists their
/// problems (its bodies are placed on that skeleton, so are not checked).
#[test]
fn a_ragdoll_file_with_bad_bones_lists_the_bones_problems() {
    let text = format!(
        "name = \"x\"\n\n{BAD_BONES}\n[[body]]\nname = \"a\"\nsegment = [[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]]\nradius = 0.1\nmass = 1.0\n"
    );
    let problems = RagdollDesc::check_toml(&text).unwrap_err();
    assert_eq!(problems.len(), 3, "{problems:?}");
    assert_eq!(
        problems[0].to_string(),
        "line 7: bone `hips`: parent `pelvis` is not a bone of the skeleton"
    );
}

#[test]
fn a_syntax_error_names_the_table_it_is_in() {
    let text = "name = \"x\"\n\n[[body]]\nname = \"hips\"\nsegment = [[0.0, 1.0, 0.0], [0.0, 0.5, 0.0]]\nmass = 1.0\n";
    let problems = RagdollDesc::check_toml(text).unwrap_err();
    assert_eq!(problems.len(), 1);
    assert_eq!(
        problems[0].to_string(),
        "malformed ragdoll file: line 3: body `hips`: missing field `radius`"
    );
}
