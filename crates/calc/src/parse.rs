//! Parser of .cal text: statements `name = e;`, `name : e;`, `f(a,b) = e;`, `$N = e;`,
//! nested `{ … }` comments, and expressions with Radiance's precedence (`^` right
//! associative and above unary minus's operand only, so `-2^2` is 4).

use crate::ast::{BinOp, Def, Expr, Lhs, Pos};

/// A syntax error: message and position.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    /// What was expected or found.
    pub message: String,
    /// Where.
    pub pos: Pos,
}

/// The deepest expression accepted (nesting of parentheses, calls and `^`, and the length
/// of a chain of `+`/`*` terms, which the tree holds as nesting): deeper input is a syntax
/// error rather than a stack overflow. The tools parse, compile and evaluate on threads
/// with stacks sized for it (`fenestra_cli::threads::STACK_BYTES`).
pub const MAX_DEPTH: usize = 50_000;

/// Depth of an expression tree (without recursion).
pub fn depth(e: &Expr) -> usize {
    let mut most = 0;
    let mut todo = vec![(e, 1usize)];
    while let Some((e, d)) = todo.pop() {
        most = most.max(d);
        match e {
            Expr::Num(_) | Expr::Name(..) | Expr::Chan(..) => {}
            Expr::Call(_, args, _) => todo.extend(args.iter().map(|a| (a, d + 1))),
            Expr::Neg(a) => todo.push((a, d + 1)),
            Expr::Bin(_, a, b) => {
                todo.push((a, d + 1));
                todo.push((b, d + 1));
            }
        }
    }
    most
}

/// Parses a whole source into definitions.
pub fn parse_defs(text: &str, src: u32) -> Result<Vec<Def>, SyntaxError> {
    let mut p = Parser::new(text, src);
    let mut defs = Vec::new();
    loop {
        p.skip_ws()?;
        match p.peek() {
            None => break,
            Some(';') => {
                p.bump();
                continue;
            }
            _ => {}
        }
        defs.push(p.definition()?);
        p.skip_ws()?;
        match p.peek() {
            None => break,
            Some(';') => {
                p.bump();
            }
            _ => return Err(p.err("';' expected")),
        }
    }
    Ok(defs)
}

/// Parses a single expression (the whole text).
pub fn parse_expr(text: &str, src: u32) -> Result<Expr, SyntaxError> {
    let mut p = Parser::new(text, src);
    let e = p.e1()?;
    p.check_depth(&e)?;
    p.skip_ws()?;
    if p.peek().is_some() {
        return Err(p.err("unexpected character"));
    }
    Ok(e)
}

struct Parser {
    nest: usize,
    chars: Vec<char>,
    i: usize,
    line: u32,
    col: u32,
    src: u32,
}

fn is_name_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '`'
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '`'
}

/// Strips the trailing global-context mark: `` x` `` names the global `x`.
fn normalise_name(s: String) -> String {
    if s.len() > 1 && s.ends_with('`') {
        s.trim_end_matches('`').to_string()
    } else {
        s
    }
}

impl Parser {
    fn new(text: &str, src: u32) -> Self {
        Parser {
            nest: 0,
            chars: text.chars().collect(),
            i: 0,
            line: 1,
            col: 1,
            src,
        }
    }

    fn pos(&self) -> Pos {
        Pos {
            src: self.src,
            line: self.line,
            col: self.col,
        }
    }

    fn err(&self, msg: &str) -> SyntaxError {
        SyntaxError {
            message: msg.to_string(),
            pos: self.pos(),
        }
    }

    fn peek(&self) -> Option<char> {
        self.chars.get(self.i).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.chars.get(self.i).copied()?;
        self.i += 1;
        if c == '\n' {
            self.line += 1;
            self.col = 1;
        } else {
            self.col += 1;
        }
        Some(c)
    }

    /// Skips white space and (nested) `{ … }` comments.
    fn skip_ws(&mut self) -> Result<(), SyntaxError> {
        loop {
            match self.peek() {
                Some(c) if c.is_whitespace() => {
                    self.bump();
                }
                Some('{') => {
                    let start = self.pos();
                    let mut depth = 0usize;
                    loop {
                        match self.bump() {
                            Some('{') => depth += 1,
                            Some('}') => {
                                depth -= 1;
                                if depth == 0 {
                                    break;
                                }
                            }
                            Some(_) => {}
                            None => {
                                return Err(SyntaxError {
                                    message: "unterminated comment (missing '}')".into(),
                                    pos: start,
                                })
                            }
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn name(&mut self) -> Result<String, SyntaxError> {
        self.skip_ws()?;
        match self.peek() {
            Some(c) if is_name_start(c) => {}
            _ => return Err(self.err("illegal variable name")),
        }
        let mut s = String::new();
        while let Some(c) = self.peek().filter(|&c| is_name_char(c)) {
            if s.len() < 127 {
                s.push(c);
            }
            self.bump();
        }
        Ok(normalise_name(s))
    }

    fn definition(&mut self) -> Result<Def, SyntaxError> {
        self.skip_ws()?;
        let pos = self.pos();
        let lhs = if self.peek() == Some('$') {
            self.bump();
            Lhs::Chan(self.uint()?)
        } else {
            let name = self.name()?;
            self.skip_ws()?;
            if self.peek() == Some('(') {
                self.bump();
                let mut params = Vec::new();
                loop {
                    params.push(self.name()?);
                    self.skip_ws()?;
                    match self.peek() {
                        Some(',') => {
                            self.bump();
                        }
                        Some(')') => {
                            self.bump();
                            break;
                        }
                        _ => return Err(self.err("')' expected")),
                    }
                }
                Lhs::Func(name, params)
            } else {
                Lhs::Var(name)
            }
        };
        self.skip_ws()?;
        let constant = match self.peek() {
            Some('=') => false,
            Some(':') => true,
            _ => return Err(self.err("'=' or ':' expected")),
        };
        self.bump();
        let body = self.e1()?;
        self.check_depth(&body)?;
        Ok(Def {
            lhs,
            constant,
            body,
            pos,
        })
    }

    fn uint(&mut self) -> Result<u32, SyntaxError> {
        let mut v: u64 = 0;
        let mut any = false;
        while let Some(d) = self.peek().and_then(|c| c.to_digit(10)) {
            v = (v * 10 + d as u64).min(u32::MAX as u64);
            any = true;
            self.bump();
        }
        if !any {
            return Err(self.err("unexpected character"));
        }
        Ok(v as u32)
    }

    /// A tree deeper than [`MAX_DEPTH`] is an error.
    fn check_depth(&self, e: &Expr) -> Result<(), SyntaxError> {
        if depth(e) > MAX_DEPTH {
            return Err(self.err(&format!(
                "expression too deep (more than {MAX_DEPTH} levels of nesting or chained terms)"
            )));
        }
        Ok(())
    }

    /// Enters one nesting level (parentheses, arguments, `^`), refusing more than
    /// [`MAX_DEPTH`].
    fn enter(&mut self) -> Result<(), SyntaxError> {
        self.nest += 1;
        if self.nest > MAX_DEPTH {
            return Err(self.err(&format!(
                "expression nested too deeply (more than {MAX_DEPTH} levels)"
            )));
        }
        Ok(())
    }

    /// `E1 := E1 ('+'|'-') E2 | E2`
    fn e1(&mut self) -> Result<Expr, SyntaxError> {
        self.enter()?;
        let e = self.e1_terms();
        self.nest -= 1;
        e
    }

    fn e1_terms(&mut self) -> Result<Expr, SyntaxError> {
        let mut e = self.e2()?;
        loop {
            self.skip_ws()?;
            let op = match self.peek() {
                Some('+') => BinOp::Add,
                Some('-') => BinOp::Sub,
                _ => return Ok(e),
            };
            self.bump();
            let r = self.e2()?;
            e = Expr::Bin(op, Box::new(e), Box::new(r));
        }
    }

    /// `E2 := E2 ('*'|'/') E3 | E3`
    fn e2(&mut self) -> Result<Expr, SyntaxError> {
        let mut e = self.e3()?;
        loop {
            self.skip_ws()?;
            let op = match self.peek() {
                Some('*') => BinOp::Mul,
                Some('/') => BinOp::Div,
                _ => return Ok(e),
            };
            self.bump();
            let r = self.e3()?;
            e = Expr::Bin(op, Box::new(e), Box::new(r));
        }
    }

    /// `E3 := E4 '^' E3 | E4`
    fn e3(&mut self) -> Result<Expr, SyntaxError> {
        let e = self.e4()?;
        self.skip_ws()?;
        if self.peek() == Some('^') {
            self.bump();
            self.enter()?;
            let r = self.e3();
            self.nest -= 1;
            return Ok(Expr::Bin(BinOp::Pow, Box::new(e), Box::new(r?)));
        }
        Ok(e)
    }

    /// `E4 := '-' E5 | '+' E5 | E5`
    fn e4(&mut self) -> Result<Expr, SyntaxError> {
        self.skip_ws()?;
        match self.peek() {
            Some('-') => {
                self.bump();
                let e = self.e5()?;
                Ok(match e {
                    Expr::Num(v) => Expr::Num(-v),
                    e => Expr::Neg(Box::new(e)),
                })
            }
            Some('+') => {
                self.bump();
                self.e5()
            }
            _ => self.e5(),
        }
    }

    /// `E5 := '(' E1 ')' | $N | name | name '(' E1 {',' E1} ')' | number`
    fn e5(&mut self) -> Result<Expr, SyntaxError> {
        self.skip_ws()?;
        let pos = self.pos();
        match self.peek() {
            Some('(') => {
                self.bump();
                let e = self.e1()?;
                self.skip_ws()?;
                if self.peek() != Some(')') {
                    return Err(self.err("')' expected"));
                }
                self.bump();
                Ok(e)
            }
            Some('$') => {
                self.bump();
                Ok(Expr::Chan(self.uint()?, pos))
            }
            Some(c) if is_name_start(c) => {
                let name = self.name()?;
                self.skip_ws()?;
                if self.peek() == Some('(') {
                    self.bump();
                    let mut args = Vec::new();
                    loop {
                        args.push(self.e1()?);
                        self.skip_ws()?;
                        match self.peek() {
                            Some(',') => {
                                self.bump();
                            }
                            Some(')') => {
                                self.bump();
                                break;
                            }
                            _ => return Err(self.err("')' expected")),
                        }
                    }
                    Ok(Expr::Call(name, args, pos))
                } else {
                    Ok(Expr::Name(name, pos))
                }
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            _ => Err(self.err("unexpected character")),
        }
    }

    fn number(&mut self) -> Result<Expr, SyntaxError> {
        let mut s = String::new();
        let mut digits = 0;
        while let Some(c) = self.peek().filter(|c| c.is_ascii_digit()) {
            s.push(c);
            digits += 1;
            self.bump();
        }
        if self.peek() == Some('.') {
            s.push('.');
            self.bump();
            while let Some(c) = self.peek().filter(|c| c.is_ascii_digit()) {
                s.push(c);
                digits += 1;
                self.bump();
            }
        }
        if digits == 0 {
            return Err(self.err("badly formed number"));
        }
        if matches!(self.peek(), Some('e' | 'E')) {
            s.push('e');
            self.bump();
            if let Some(c) = self.peek().filter(|&c| c == '+' || c == '-') {
                s.push(c);
                self.bump();
            }
            let mut ed = 0;
            while let Some(c) = self.peek().filter(|c| c.is_ascii_digit()) {
                s.push(c);
                ed += 1;
                self.bump();
            }
            if ed == 0 {
                return Err(self.err("missing exponent"));
            }
        }
        s.parse::<f64>()
            .map(Expr::Num)
            .map_err(|_| self.err("badly formed number"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(s: &str) -> Expr {
        parse_expr(s, 0).unwrap()
    }

    #[test]
    fn unary_minus_binds_to_primary() {
        // -2^2 parses as (-2)^2
        assert_eq!(
            one("-2^2"),
            Expr::Bin(
                BinOp::Pow,
                Box::new(Expr::Num(-2.0)),
                Box::new(Expr::Num(2.0))
            )
        );
    }

    #[test]
    fn nested_comments_and_statements() {
        let d = parse_defs("{a {b} c} x = 1; ; f(a,b) : a+b {end}", 0).unwrap();
        assert_eq!(d.len(), 2);
        assert!(d[1].constant);
    }

    #[test]
    fn errors_have_positions() {
        let e = parse_defs("a = 1;\nb = 2 3", 0).unwrap_err();
        assert_eq!((e.pos.line, e.pos.col), (2, 7));
        assert_eq!(e.message, "';' expected");
        assert!(parse_expr("1e", 0).is_err());
        assert!(parse_expr(".", 0).is_err());
        assert!(parse_expr("--2", 0).is_err());
    }
}
