//! Where runs are kept: the [`LotStore`] trait, opening a store from its address, and the
//! address with its password hidden for messages.

use std::path::Path;

use super::{LotError, PgStore, Run, SqliteStore};

/// A place runs are kept: the same schema in SQLite or PostgreSQL.
pub trait LotStore {
    /// Record `run` (its `id` and `latest` are ignored) in one transaction; returns its id.
    fn add(&mut self, run: &Run) -> Result<i64, LotError>;
    /// Every run, oldest first, with [`Run::latest`] set.
    fn runs(&mut self) -> Result<Vec<Run>, LotError>;
    /// The schema version the store holds.
    fn schema_version(&mut self) -> Result<i64, LotError>;
}

/// `db` (a lot's `--db`: a URL, a `key=value` connection string or a file path) as a message
/// may show it: every password replaced by `***`. Masked: the URL's `user:PASSWORD@` (the
/// credentials end at the first `@`, as the PostgreSQL URL parser reads them, or at the last
/// one before the query when there are several, so that no part of a password with an `@`
/// shows), URL query parameters and `key=value` settings whose key ends in `password`
/// (`password`, `sslpassword`; any case, percent-encoded or not), quoted values whole.
/// The command line and Python show a lot's name only through this.
pub(crate) fn redact_db(db: &str) -> String {
    let Some((scheme, rest)) = db.split_once("://") else {
        return redact_conninfo(db);
    };
    let before_query = rest.split('?').next().unwrap_or(rest);
    let at = before_query.rfind('@').or_else(|| rest.find('@'));
    let (auth, tail) = match at {
        Some(k) => (Some(&rest[..k]), &rest[k + 1..]),
        None => (None, rest),
    };
    let mut out = format!("{scheme}://");
    if let Some(auth) = auth {
        match auth.split_once(':') {
            Some((user, _)) => out.push_str(&format!("{user}:***@")),
            None => out.push_str(&format!("{auth}@")),
        }
    }
    match tail.split_once('?') {
        Some((path, query)) => {
            out.push_str(path);
            out.push('?');
            let params: Vec<String> = query
                .split('&')
                .map(|p| match p.split_once('=') {
                    Some((k, _)) if is_password_key(&percent_decode(k)) => format!("{k}=***"),
                    _ => p.to_owned(),
                })
                .collect();
            out.push_str(&params.join("&"));
        }
        None => out.push_str(tail),
    }
    out
}

/// A connection setting that holds a secret.
fn is_password_key(key: &str) -> bool {
    key.trim().to_ascii_lowercase().ends_with("password")
}

/// `%XX` escapes decoded (others kept as they are).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A `key=value` connection string (libpq's form: values bare up to white space, or in
/// single quotes with `\'` escapes) with the values of password keys masked; any other text
/// (a file path) as it is, unless it holds such a setting.
fn redact_conninfo(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(eq) = rest.find('=') {
        let (head, after) = rest.split_at(eq);
        // The key: the word just before `=` (white space allowed around it).
        let key = head.trim_end();
        let key_start = key.rfind(|c: char| c.is_whitespace()).map_or(0, |k| k + 1);
        let is_secret = is_password_key(&key[key_start..]);
        out.push_str(head);
        out.push('=');
        let after = &after[1..];
        let value_start = after.len() - after.trim_start().len();
        out.push_str(&after[..value_start]);
        let value = &after[value_start..];
        let value_len = if let Some(quoted) = value.strip_prefix('\'') {
            let mut escaped = false;
            let end = quoted
                .char_indices()
                .find(|&(_, c)| {
                    let close = c == '\'' && !escaped;
                    escaped = c == '\\' && !escaped;
                    close
                })
                .map_or(quoted.len(), |(k, _)| k + 1);
            1 + end
        } else {
            value.find(char::is_whitespace).unwrap_or(value.len())
        };
        if is_secret {
            out.push_str("***");
        } else {
            out.push_str(&value[..value_len]);
        }
        rest = &value[value_len..];
    }
    out.push_str(rest);
    out
}

/// A stored schema version below 1 is refused before anything is written: upgrades run from
/// the version found, and below 1 there is none to run from (the tables would be stamped
/// current without them, and the lot unusable for good).
pub(crate) fn check_known(db: &str, version: i64) -> Result<(), LotError> {
    if version < 1 {
        return Err(LotError::InvalidSchema {
            db: db.to_string(),
            found: version,
        });
    }
    Ok(())
}

/// Open the lot at `db`: a `postgres://` or `postgresql://` URL, else an SQLite file path.
/// `create`: make the file and the schema if missing (`lot add`); otherwise a missing file is
/// [`LotError::Missing`]. `busy_timeout_ms`: how long a writer waits for another (SQLite).
pub fn open_store(
    db: &str,
    create: bool,
    busy_timeout_ms: u64,
) -> Result<Box<dyn LotStore>, LotError> {
    if db.starts_with("postgres://") || db.starts_with("postgresql://") {
        Ok(Box::new(PgStore::open(db, create)?))
    } else {
        Ok(Box::new(SqliteStore::open(
            Path::new(db),
            create,
            busy_timeout_ms,
        )?))
    }
}
