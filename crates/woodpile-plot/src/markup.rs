//! Labels as a physicist writes them: a small TeX-like markup turned into Unicode, which the
//! embedded font draws the same way in PNG and SVG. `E_{tr}` is E with the subscript "tr",
//! `\varepsilon_1` is ε₁, `u'_n` is u′ₙ, `10^{-3}` is 10⁻³.
//!
//! - `_x` and `^x` set one character below or above the line when it ends a word (`u_n`,
//!   `x^2`; `E_tr` stays as typed, so column names pass unchanged); `_{...}` and `^{...}` set
//!   a group.
//!   Digits, `+ - = ( )`, most lowercase Latin letters and some Greek ones have such forms;
//!   anything else is an error that names the character, not a silently wrong label.
//! - `\name` is a Greek letter (`\alpha` ... `\omega`, `\Gamma` ... `\Omega`, `\varepsilon`,
//!   `\varphi`), `\,` a thin space; `'` is a prime (′). Unlike TeX, a space after a command is
//!   kept: what is typed is what is drawn.
//! - Text without markup is returned unchanged, so plain Unicode labels (ε, u′ₙ) work as they
//!   are. `\_`, `\^`, `\'` and `\\` give the character itself.

/// The Unicode rendering of `text`, or why it has none.
pub fn markup(text: &str) -> Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '_' | '^' => {
                let group: String = match chars.next() {
                    Some('{') => {
                        let mut group = String::new();
                        loop {
                            match chars.next() {
                                Some('}') => break,
                                Some('\\') => group.push_str(&command(&mut chars)?),
                                Some(c) => group.push(c),
                                None => return Err(format!("`{c}{{` is not closed in \"{text}\"")),
                            }
                        }
                        group
                    }
                    Some('\\') => command(&mut chars)?,
                    // One character only when it ends the word: `u_n`, `x^2`; `E_tr` is
                    // plain text (braces set a group: `E_{tr}`).
                    Some(x) if chars.peek().is_some_and(|n| n.is_alphanumeric()) => {
                        out.push(c);
                        out.push(x);
                        continue;
                    }
                    Some(c) => c.to_string(),
                    None => return Err(format!("`{c}` ends \"{text}\" with nothing to set")),
                };
                for g in group.chars() {
                    let shifted = if c == '_' {
                        subscript(g)
                    } else {
                        superscript(g)
                    };
                    out.push(shifted.ok_or_else(|| {
                        let place = if c == '_' { "subscript" } else { "superscript" };
                        format!("`{g}` has no {place} form (in \"{text}\")")
                    })?);
                }
            }
            '\\' => out.push_str(&command(&mut chars)?),
            '\'' => out.push('′'),
            c => out.push(c),
        }
    }
    Ok(out)
}

/// The text of a `\command` whose backslash has been read.
fn command(chars: &mut std::iter::Peekable<std::str::Chars<'_>>) -> Result<String, String> {
    match chars.peek() {
        Some(&c) if matches!(c, '_' | '^' | '\'' | '\\' | '{' | '}') => {
            chars.next();
            return Ok(c.to_string());
        }
        Some(',') => {
            chars.next();
            return Ok("\u{2009}".into());
        }
        _ => {}
    }
    let mut name = String::new();
    while let Some(&c) = chars.peek() {
        if !c.is_ascii_alphabetic() {
            break;
        }
        name.push(c);
        chars.next();
    }
    greek(&name)
        .map(String::from)
        .ok_or_else(|| format!("unknown command `\\{name}` (Greek letters, `\\,`)"))
}

fn greek(name: &str) -> Option<char> {
    const LETTERS: [(&str, char); 37] = [
        ("alpha", 'α'),
        ("beta", 'β'),
        ("gamma", 'γ'),
        ("delta", 'δ'),
        ("epsilon", 'ϵ'),
        ("varepsilon", 'ε'),
        ("zeta", 'ζ'),
        ("eta", 'η'),
        ("theta", 'θ'),
        ("iota", 'ι'),
        ("kappa", 'κ'),
        ("lambda", 'λ'),
        ("mu", 'μ'),
        ("nu", 'ν'),
        ("xi", 'ξ'),
        ("pi", 'π'),
        ("rho", 'ρ'),
        ("sigma", 'σ'),
        ("tau", 'τ'),
        ("upsilon", 'υ'),
        ("phi", 'ϕ'),
        ("varphi", 'φ'),
        ("chi", 'χ'),
        ("psi", 'ψ'),
        ("omega", 'ω'),
        ("Gamma", 'Γ'),
        ("Delta", 'Δ'),
        ("Theta", 'Θ'),
        ("Lambda", 'Λ'),
        ("Xi", 'Ξ'),
        ("Pi", 'Π'),
        ("Sigma", 'Σ'),
        ("Phi", 'Φ'),
        ("Psi", 'Ψ'),
        ("Omega", 'Ω'),
        ("prime", '′'),
        ("infty", '∞'),
    ];
    LETTERS.iter().find(|(n, _)| *n == name).map(|&(_, c)| c)
}

fn subscript(c: char) -> Option<char> {
    const FROM: &str = "0123456789+-=()aehijklmnoprstuvxβγρφχ";
    const TO: &str = "₀₁₂₃₄₅₆₇₈₉₊₋₌₍₎ₐₑₕᵢⱼₖₗₘₙₒₚᵣₛₜᵤᵥₓᵦᵧᵨᵩᵪ";
    shift(c, FROM, TO)
}

fn superscript(c: char) -> Option<char> {
    const FROM: &str = "0123456789+-=()abcdefghijklmnoprstuvwxyzABDEGHIJKLMNOPRTUVWβγδφχ′";
    const TO: &str = "⁰¹²³⁴⁵⁶⁷⁸⁹⁺⁻⁼⁽⁾ᵃᵇᶜᵈᵉᶠᵍʰⁱʲᵏˡᵐⁿᵒᵖʳˢᵗᵘᵛʷˣʸᶻᴬᴮᴰᴱᴳᴴᴵᴶᴷᴸᴹᴺᴼᴾᴿᵀᵁⱽᵂᵝᵞᵟᵠᵡ′";
    shift(c, FROM, TO)
}

fn shift(c: char, from: &str, to: &str) -> Option<char> {
    from.chars()
        .position(|f| f == c)
        .and_then(|k| to.chars().nth(k))
}

#[cfg(test)]
mod tests {
    use super::markup;

    #[test]
    fn subscripts_superscripts_greek_and_primes() {
        assert_eq!(markup("E_{tr}").unwrap(), "Eₜᵣ");
        assert_eq!(markup("\\varepsilon_1").unwrap(), "ε₁");
        assert_eq!(markup("u'_n").unwrap(), "u′ₙ");
        assert_eq!(markup("10^{-3}").unwrap(), "10⁻³");
        assert_eq!(markup("\\kappa (u - v)^p").unwrap(), "κ (u - v)ᵖ");
        assert_eq!(markup("\\varepsilon = m/M").unwrap(), "ε = m/M");
    }

    #[test]
    fn plain_text_and_unicode_pass_unchanged() {
        for text in [
            "energy fraction",
            "ε = m/M",
            "velocity u′ₙ",
            "t (dimensionless time)",
        ] {
            assert_eq!(markup(text).unwrap(), text);
        }
        assert_eq!(markup("a\\_b").unwrap(), "a_b");
        assert_eq!(markup("best E_tr so far").unwrap(), "best E_tr so far");
        assert_eq!(markup("log10_step").unwrap(), "log10_step");
    }

    #[test]
    fn what_cannot_be_set_is_an_error_naming_it() {
        assert!(markup("E_{q}")
            .unwrap_err()
            .contains("`q` has no subscript form"));
        assert!(markup("E_{tr").unwrap_err().contains("not closed"));
        assert!(markup("x_").unwrap_err().contains("nothing to set"));
        assert!(markup("\\foo")
            .unwrap_err()
            .contains("unknown command `\\foo`"));
    }
}
