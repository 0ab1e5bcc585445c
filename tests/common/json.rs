//! A minimal JSON reader for the test fixtures (tests/fixtures/*.json,
//! written by the scripts/ that make them), without a JSON crate.

/// A JSON value.
#[derive(Debug, Clone)]
pub enum Json {
    /// true, false or null (the fixture's tests never read them).
    Literal,
    Num(f64),
    Str(String),
    Arr(Vec<Json>),
    Obj(Vec<(String, Json)>),
}

impl Json {
    pub fn parse(text: &str) -> Json {
        let b = text.as_bytes();
        let mut i = 0;
        let v = Self::value(b, &mut i);
        Self::ws(b, &mut i);
        assert_eq!(i, b.len(), "trailing characters in fixture");
        v
    }

    fn ws(b: &[u8], i: &mut usize) {
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
    }

    fn value(b: &[u8], i: &mut usize) -> Json {
        Self::ws(b, i);
        match b[*i] {
            b'{' => {
                *i += 1;
                let mut fields = vec![];
                loop {
                    Self::ws(b, i);
                    if b[*i] == b'}' {
                        *i += 1;
                        return Json::Obj(fields);
                    }
                    let Json::Str(key) = Self::value(b, i) else {
                        panic!("object key at byte {i}")
                    };
                    Self::ws(b, i);
                    assert_eq!(b[*i], b':', "':' expected at byte {i}");
                    *i += 1;
                    fields.push((key, Self::value(b, i)));
                    Self::ws(b, i);
                    if b[*i] == b',' {
                        *i += 1;
                    }
                }
            }
            b'[' => {
                *i += 1;
                let mut items = vec![];
                loop {
                    Self::ws(b, i);
                    if b[*i] == b']' {
                        *i += 1;
                        return Json::Arr(items);
                    }
                    items.push(Self::value(b, i));
                    Self::ws(b, i);
                    if b[*i] == b',' {
                        *i += 1;
                    }
                }
            }
            b'"' => {
                *i += 1;
                let start = *i;
                while b[*i] != b'"' {
                    *i += if b[*i] == b'\\' { 2 } else { 1 };
                }
                *i += 1;
                Json::Str(String::from_utf8_lossy(&b[start..*i - 1]).into_owned())
            }
            b't' | b'f' | b'n' => {
                let word = [b"true".as_slice(), b"false", b"null"]
                    .into_iter()
                    .find(|w| b[*i..].starts_with(w))
                    .unwrap_or_else(|| panic!("bad literal at byte {i}"));
                *i += word.len();
                Json::Literal
            }
            _ => {
                let start = *i;
                while *i < b.len()
                    && matches!(b[*i], b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E')
                {
                    *i += 1;
                }
                let s = std::str::from_utf8(&b[start..*i]).unwrap();
                Json::Num(s.parse().unwrap_or_else(|_| panic!("bad number {s:?}")))
            }
        }
    }

    pub fn get(&self, key: &str) -> &Json {
        match self {
            Json::Obj(f) => f
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v)
                .unwrap_or_else(|| panic!("fixture key {key:?} missing")),
            _ => panic!("{key:?}: not an object"),
        }
    }

    pub fn num(&self, key: &str) -> f64 {
        match self.get(key) {
            Json::Num(x) => *x,
            v => panic!("{key:?}: not a number: {v:?}"),
        }
    }

    pub fn arr(&self, key: &str) -> &[Json] {
        match self.get(key) {
            Json::Arr(a) => a,
            v => panic!("{key:?}: not an array: {v:?}"),
        }
    }

    pub fn as_num(&self) -> f64 {
        match self {
            Json::Num(x) => *x,
            v => panic!("not a number: {v:?}"),
        }
    }
}
