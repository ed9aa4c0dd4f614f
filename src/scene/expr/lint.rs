//! Reading conventions of exmex that differ from mathematics, rejected before parsing, and the
//! rewriting of what exmex cannot read (scientific notation, `pi`).

use std::iter::Peekable;
use std::str::Chars;

/// A token of an expression, as far as the checks need to know it.
#[derive(Clone, Copy, PartialEq)]
enum Tok {
    Atom,
    Ident,
    /// min, max, atan2: exmex's two-argument functions, which it cannot nest
    Binary,
    Open,
    Close,
    Comma,
    Op(char),
}

/// Reject the two constructs whose exmex reading differs from the usual mathematical one:
/// a unary minus in front of a power (exmex reads `-x^2` as `(-x)^2`) and chained powers
/// (exmex reads `2^x^2` as `(2^x)^2`). Both must be parenthesised explicitly.
/// Returns the text with scientific-notation literals (`1.2e-3`, which exmex cannot read) written out.
pub(super) fn lint(text: &str) -> std::result::Result<String, String> {
    let (out, toks) = rewrite(text)?;
    check_nesting(&toks)?;
    check_powers(&toks)?;
    Ok(out)
}

/// The text rewritten for exmex (numbers without exponent notation, `pi` as `PI`) and its tokens.
fn rewrite(text: &str) -> std::result::Result<(String, Vec<Tok>), String> {
    let mut out = String::with_capacity(text.len());
    let mut toks = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(&c) = chars.peek() {
        if c.is_whitespace() {
            out.push(c);
            chars.next();
        } else if c.is_ascii_digit() || c == '.' {
            number(&mut chars, &mut out)?;
            toks.push(Tok::Atom);
        } else if c.is_alphanumeric() || c == '_' {
            let mut name = String::new();
            while let Some(d) = chars.next_if(|d| d.is_alphanumeric() || *d == '_') {
                name.push(d);
            }
            // `pi` is accepted for exmex's `PI`
            out.push_str(if name == "pi" { "PI" } else { &name });
            toks.push(if matches!(name.as_str(), "min" | "max" | "atan2") { Tok::Binary } else { Tok::Ident });
        } else {
            out.push(c);
            chars.next();
            toks.push(match c {
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                other => Tok::Op(other),
            });
        }
    }
    Ok((out, toks))
}

/// Read the number literal at the front of `chars` into `out`, written out without exponent notation.
fn number(chars: &mut Peekable<Chars<'_>>, out: &mut String) -> std::result::Result<(), String> {
    let mut lit = String::new();
    while let Some(d) = chars.next_if(|d| d.is_ascii_digit() || *d == '.') {
        lit.push(d);
    }
    // exponent notation such as 1e-3
    if chars.peek().is_some_and(|d| *d == 'e' || *d == 'E') {
        let mut look = chars.clone();
        look.next();
        let sign = look.next_if(|d| *d == '-' || *d == '+');
        if look.peek().is_some_and(|d| d.is_ascii_digit()) {
            chars.next();
            lit.push('e');
            if let Some(sg) = sign {
                chars.next();
                lit.push(sg);
            }
            while let Some(d) = chars.next_if(|d| d.is_ascii_digit()) {
                lit.push(d);
            }
        }
    }
    let v: f64 = lit.parse().map_err(|_| format!("malformed number `{lit}`"))?;
    if lit.contains('e') {
        // Rust's Display never uses exponent notation and round-trips exactly
        out.push_str(&format!("{v}"));
    } else {
        out.push_str(&lit);
    }
    Ok(())
}

/// Index just past the operand starting at token i (atom, identifier, call or parenthesised group).
fn skip_operand(toks: &[Tok], i: usize) -> usize {
    let mut j = i;
    if matches!(toks.get(j), Some(Tok::Ident | Tok::Binary)) && toks.get(j + 1) == Some(&Tok::Open) {
        j += 1;
    }
    if toks.get(j) == Some(&Tok::Open) {
        let mut depth = 0;
        while j < toks.len() {
            match toks[j] {
                Tok::Open => depth += 1,
                Tok::Close => {
                    depth -= 1;
                    if depth == 0 {
                        return j + 1;
                    }
                }
                _ => {}
            }
            j += 1;
        }
        return j;
    }
    j + 1
}

/// Refuse a two-argument call (min, max, atan2) inside another, which exmex cannot read.
fn check_nesting(toks: &[Tok]) -> std::result::Result<(), String> {
    // depth of parentheses at which each open two-argument call started
    let mut calls: Vec<usize> = Vec::new();
    let mut depth = 0usize;
    for t in toks {
        match t {
            Tok::Open => depth += 1,
            Tok::Close => {
                depth = depth.saturating_sub(1);
                if calls.last() == Some(&depth) {
                    calls.pop();
                }
            }
            Tok::Binary => {
                if !calls.is_empty() {
                    return Err("exmex cannot nest min/max/atan2 inside another min/max/atan2; \
                                write max(a, b) as (a + b + abs(a - b))/2"
                        .into());
                }
                calls.push(depth);
            }
            _ => {}
        }
    }
    Ok(())
}

/// Refuse a unary minus before a power and chained powers (the module doc).
fn check_powers(toks: &[Tok]) -> std::result::Result<(), String> {
    for i in 0..toks.len() {
        let unary = toks[i] == Tok::Op('-') && (i == 0 || matches!(toks[i - 1], Tok::Open | Tok::Comma | Tok::Op(_)));
        if unary && toks.get(skip_operand(toks, i + 1)) == Some(&Tok::Op('^')) {
            return Err(
                "ambiguous unary minus before a power: exmex reads -a^b as (-a)^b; write -(a^b) or (-a)^b".into()
            );
        }
        if toks[i] == Tok::Op('^') {
            let mut j = i + 1;
            while toks.get(j).is_some_and(|t| matches!(t, Tok::Op('-') | Tok::Op('+'))) {
                j += 1;
            }
            if toks.get(skip_operand(toks, j)) == Some(&Tok::Op('^')) {
                return Err("chained powers: exmex reads a^b^c as (a^b)^c; parenthesise, e.g. a^(b^c)".into());
            }
        }
    }
    Ok(())
}
