//! `${VAR}` in configured paths and command lines (scenario meshes and selections, external
//! methods' commands): expanded from the environment, an unset variable an error that names it.

/// `text` with every `${VAR}` replaced by the variable's value; `what` names the setting in errors.
pub fn expand(text: &str, what: &str) -> Result<String, String> {
    expand_with(text, what, &[])
}

/// [`expand`], with `given` (name, value) pairs taking precedence over the environment.
pub fn expand_with(text: &str, what: &str, given: &[(&str, &str)]) -> Result<String, String> {
    let mut out = text.to_string();
    let mut from = 0;
    while let Some(found) = out[from..].find("${") {
        let start = from + found;
        let Some(len) = out[start..].find('}') else {
            return Err(format!("`{text}`: unclosed ${{ in {what}"));
        };
        let name = out[start + 2..start + len].to_string();
        let value = match given.iter().find(|(n, _)| *n == name) {
            Some((_, v)) => v.to_string(),
            None => std::env::var(&name)
                .map_err(|_| format!("`{text}` needs the environment variable {name} ({what})"))?,
        };
        out.replace_range(start..start + len + 1, &value);
        // A value is not expanded again.
        from = start + value.len();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variables_expand_once_and_unset_ones_are_named() {
        std::env::set_var("DEFORMBENCH_TEST_VARIABLE", "a${B}");
        assert_eq!(expand("x/${DEFORMBENCH_TEST_VARIABLE}/y", "p").unwrap(), "x/a${B}/y");
        let err = expand("${DEFORMBENCH_SURELY_UNSET}/m.off", "the mesh").unwrap_err();
        assert!(err.contains("DEFORMBENCH_SURELY_UNSET") && err.contains("the mesh"), "{err}");
        assert!(expand("${OPEN", "p").unwrap_err().contains("unclosed"));
        let given = [("DEFORMBENCH_SURELY_UNSET", "/py")];
        assert_eq!(expand_with("${DEFORMBENCH_SURELY_UNSET} x", "p", &given).unwrap(), "/py x");
    }
}
