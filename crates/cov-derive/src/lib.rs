//! # cov-derive: `#[derive(OperatorSpec)]`
//!
//! Declares an operator's parameters once, on the fields of its spec struct. See
//! `cov_core::spec` for the attributes and a complete example; the derive is re-exported
//! as `cov_core::OperatorSpec`.
//!
//! | attribute | on | meaning |
//! |---|---|---|
//! | `#[operator(name = "Travel")]` | struct | name in files (default: the struct's name without `Spec`) |
//! | `#[operator(summary = "…")]` | struct | one line for `covtrace list` (required) |
//! | `/// text` | field | the parameter's documentation |
//! | `#[param(unit = "m")]` | field | its unit (default: none) |
//! | `#[param(default)]`, `#[param(default = expr)]` | field | optional, with `Default::default()` or `expr` (taken as the field's type for a number: `default = 2` on a `u32`; a number must lie inside the bounds written as numbers, or the derive refuses it) |
//! | `#[param(nested)]` | field | a `Chain` written as an operator list (read with the caller's registry) |
//! | `#[param(positive)]`, `#[param(non_negative)]` | field | domain `> 0`, `≥ 0` |
//! | `#[param(gt = a, le = b)]` (and `ge`, `lt`) | field | bounds; `a`, `b` are numbers or other fields (`gt = self.focal_length`) |
//! | `#[param(finite)]` | field | finite (implied for `f64`, `Option<f64>`, `Vec<f64>`, `[f64; N]`) |
//!
//! The operator type and its construction are given by `impl Build for Spec` (cov-core),
//! never guessed from names. The derive also gives the spec one constant per field,
//! `Spec::FIELD_NAME` (a `cov_core::Param`), through which code that reports a
//! parameter names it.

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::{format_ident, quote, quote_spanned};
use syn::{Data, DeriveInput, Expr, Fields, Ident, LitStr, spanned::Spanned};

/// Derives `cov_core::OperatorSpec` for a struct of named parameters.
#[proc_macro_derive(OperatorSpec, attributes(operator, param))]
pub fn derive_operator_spec(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as DeriveInput);
    match expand(&input) {
        Ok(t) => t.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

/// The path to cov-core as the deriving crate sees it: `cov_core` when it depends on
/// cov-core, else the facade `covtrace`, which re-exports it.
fn core_path() -> Tokens {
    use proc_macro_crate::{FoundCrate, crate_name};
    match crate_name("cov-core") {
        // cov-core never derives on itself; its doctests and tests see it as `cov_core`.
        Ok(FoundCrate::Itself) => quote!(::cov_core),
        Ok(FoundCrate::Name(n)) => {
            let id = format_ident!("{}", n);
            quote!(::#id)
        }
        Err(_) => match crate_name("covtrace") {
            Ok(FoundCrate::Name(n)) => {
                let id = format_ident!("{}", n);
                quote!(::#id)
            }
            _ => quote!(::covtrace),
        },
    }
}

struct FieldSpec {
    ident: Ident,
    ty: syn::Type,
    name: String,
    unit: String,
    doc: String,
    default: Option<Option<Expr>>,
    nested: bool,
    /// Declared bounds: at most one lower and one upper.
    bounds: Vec<(Bound, Expr)>,
    /// Checked at all: a declared domain, or a float type.
    checked: bool,
}

/// A declared bound's kind.
#[derive(Clone, Copy, PartialEq)]
enum Bound {
    Gt,
    Ge,
    Lt,
    Le,
}

impl Bound {
    fn is_lower(self) -> bool {
        matches!(self, Bound::Gt | Bound::Ge)
    }

    fn symbol(self) -> &'static str {
        match self {
            Bound::Gt => ">",
            Bound::Ge => "≥",
            Bound::Lt => "<",
            Bound::Le => "≤",
        }
    }
}

/// The value of a number written as a literal (`2`, `0.5`, `-1e-3`); `None` for any
/// other expression (a field, a constant).
fn literal(e: &Expr) -> Option<f64> {
    match e {
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) => i.base10_digits().parse().ok(),
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Float(f),
            ..
        }) => f.base10_digits().parse().ok(),
        Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => literal(&u.expr).map(|v| -v),
        _ => None,
    }
}

/// `0` as `0.0`: bounds are compared as f64.
fn as_float(e: Expr) -> Expr {
    match &e {
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) => {
            let f = syn::LitFloat::new(&format!("{}.0", i.base10_digits()), i.span());
            syn::parse_quote!(#f)
        }
        Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => {
            let inner = as_float((*u.expr).clone());
            syn::parse_quote!(-#inner)
        }
        _ => e,
    }
}

/// A bound as the docs and messages show it: `self.` dropped, `1.0` as `1`, π by name.
fn bound_text(e: &Expr) -> String {
    let t = quote!(#e)
        .to_string()
        .replace(" . ", ".")
        .replace(" :: ", "::")
        .replace("- ", "-");
    let t = t.replace("self.", "").replace("crate::", "");
    let t = match t.strip_prefix("f64::from(").and_then(|i| i.strip_suffix(')')) {
        Some(inner) => inner.to_string(),
        None => t,
    };
    let t = match t.rsplit("::").next() {
        Some("PI") => "π".to_string(),
        _ => t,
    };
    match t.strip_suffix(".0") {
        Some(n) if n.trim_start_matches('-').chars().all(|c| c.is_ascii_digit()) => n.to_string(),
        _ => t,
    }
}

/// Whether a bound is a number written in the source (else its value is shown too).
fn is_literal(e: &Expr) -> bool {
    match e {
        Expr::Lit(_) => true,
        Expr::Unary(u) => is_literal(&u.expr),
        _ => false,
    }
}

/// The domain in words: `> 0`, `in (0, 1]`, `finite`.
fn domain_text(f: &FieldSpec) -> String {
    if !f.checked {
        return String::new();
    }
    let lower = f.bounds.iter().find(|(k, _)| k.is_lower());
    let upper = f.bounds.iter().find(|(k, _)| !k.is_lower());
    match (lower, upper) {
        (Some((lk, l)), Some((uk, u))) => format!(
            "in {}{}, {}{}",
            if *lk == Bound::Gt { "(" } else { "[" },
            bound_text(l),
            bound_text(u),
            if *uk == Bound::Lt { ")" } else { "]" }
        ),
        (Some((k, b)), None) | (None, Some((k, b))) => format!("{} {}", k.symbol(), bound_text(b)),
        (None, None) => "finite".to_string(),
    }
}

/// A declared default of a field of type `ty`. A primitive integer takes the expression
/// as a value of its type, so that `default = 1` means `1u32` for a `u32` (a literal out of
/// its range is a compile error); a float takes it `as` its type (`default = 1` is `1.0`);
/// any other type converts it with `Into` (a `&str` into a `String`, say).
fn default_expr(ty: &syn::Type, e: &Expr) -> Tokens {
    let t = quote!(#ty).to_string().replace(' ', "");
    match t.as_str() {
        "f32" | "f64" => quote!(((#e) as #ty)),
        "u8" | "u16" | "u32" | "u64" | "u128" | "usize" | "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => {
            quote!({
                let default: #ty = #e;
                default
            })
        }
        _ => quote!(::core::convert::Into::into(#e)),
    }
}

/// Types checked for finiteness without a declared domain.
fn is_float(ty: &syn::Type) -> bool {
    let t = quote!(#ty).to_string().replace(' ', "");
    matches!(t.as_str(), "f64" | "Option<f64>" | "Vec<f64>") || (t.starts_with("[f64;") && t.ends_with(']'))
}

fn doc_of(attrs: &[syn::Attribute]) -> String {
    let mut lines = Vec::new();
    for a in attrs {
        if a.path().is_ident("doc")
            && let syn::Meta::NameValue(nv) = &a.meta
            && let Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
        {
            lines.push(s.value().trim().to_string());
        }
    }
    lines.join(" ").trim().to_string()
}

fn expand(input: &DeriveInput) -> syn::Result<Tokens> {
    let ty = &input.ident;
    let base = ty.to_string();
    let base = base.strip_suffix("Spec").unwrap_or(&base).to_string();
    let mut name = base;
    let mut summary: Option<String> = None;
    for a in &input.attrs {
        if !a.path().is_ident("operator") {
            continue;
        }
        a.parse_nested_meta(|m| {
            if m.path.is_ident("name") {
                name = m.value()?.parse::<LitStr>()?.value();
            } else if m.path.is_ident("op") {
                return Err(m.error(format!(
                    "`op` is not needed: name the operator type in `impl Build for {ty} {{ type Op = YourOperator; … }}`"
                )));
            } else if m.path.is_ident("summary") {
                summary = Some(m.value()?.parse::<LitStr>()?.value());
            } else {
                return Err(m.error("expected `name` or `summary`"));
            }
            Ok(())
        })?;
    }
    let summary = summary.ok_or_else(|| {
        syn::Error::new(
            input.ident.span(),
            "#[derive(OperatorSpec)] needs #[operator(summary = \"…\")]",
        )
    })?;
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new(input.span(), "OperatorSpec derives on structs"));
    };
    let fields: Vec<&syn::Field> = match &data.fields {
        Fields::Named(n) => n.named.iter().collect(),
        Fields::Unit => Vec::new(),
        Fields::Unnamed(_) => {
            return Err(syn::Error::new(
                data.fields.span(),
                "OperatorSpec needs named fields",
            ));
        }
    };
    let mut specs = Vec::new();
    for f in fields {
        let ident = f
            .ident
            .clone()
            .ok_or_else(|| syn::Error::new(f.span(), "unnamed field"))?;
        let mut unit = String::new();
        let mut default = None;
        let mut nested = false;
        let mut bounds = Vec::new();
        let mut finite = false;
        for a in &f.attrs {
            if !a.path().is_ident("param") {
                continue;
            }
            a.parse_nested_meta(|m| {
                if m.path.is_ident("unit") {
                    unit = m.value()?.parse::<LitStr>()?.value();
                } else if m.path.is_ident("default") {
                    if m.input.peek(syn::Token![=]) {
                        default = Some(Some(m.value()?.parse::<Expr>()?));
                    } else {
                        default = Some(None);
                    }
                } else if m.path.is_ident("nested") {
                    nested = true;
                } else if m.path.is_ident("finite") {
                    finite = true;
                } else if let Some(k) = ["gt", "ge", "lt", "le", "positive", "non_negative"]
                    .iter()
                    .position(|k| m.path.is_ident(k))
                {
                    use Bound::{Ge, Gt, Le, Lt};
                    let kind = [Gt, Ge, Lt, Le, Gt, Ge][k];
                    let lower = kind.is_lower();
                    if bounds.iter().any(|(b, _): &(Bound, Expr)| b.is_lower() == lower) {
                        return Err(m.error(if lower {
                            "a second lower bound: give one of `positive`, `non_negative`, `gt`, `ge`"
                        } else {
                            "a second upper bound: give one of `lt`, `le`"
                        }));
                    }
                    let e = if k >= 4 {
                        syn::parse_quote!(0.0)
                    } else {
                        as_float(m.value()?.parse::<Expr>()?)
                    };
                    bounds.push((kind, e));
                } else {
                    return Err(m.error(
                        "expected `unit`, `default`, `nested`, `finite`, `positive`, `non_negative`, `gt`, `ge`, `lt` or `le`",
                    ));
                }
                Ok(())
            })?;
        }
        // A number written as the default must lie in the bounds written as numbers: a
        // file that leaves the parameter out would be refused at a value it never wrote.
        if let Some(Some(e)) = &default
            && let Some(d) = literal(e)
        {
            for (kind, b) in &bounds {
                let Some(v) = literal(b) else { continue };
                let (inside, words) = match kind {
                    Bound::Gt => (d > v, ">"),
                    Bound::Ge => (d >= v, "≥"),
                    Bound::Lt => (d < v, "<"),
                    Bound::Le => (d <= v, "≤"),
                };
                if !inside {
                    return Err(syn::Error::new(
                        e.span(),
                        format!(
                            "the default {} is outside the parameter's domain: it must be {words} {}",
                            default_text(e),
                            default_text(b)
                        ),
                    ));
                }
            }
        }
        let name = ident.to_string().trim_start_matches("r#").to_string();
        let checked = finite || !bounds.is_empty() || is_float(&f.ty);
        specs.push(FieldSpec {
            ident,
            ty: f.ty.clone(),
            name,
            unit,
            doc: doc_of(&f.attrs),
            default,
            nested,
            bounds,
            checked,
        });
    }

    let core = core_path();
    let serde = quote!(#core::__serde);
    let names: Vec<&String> = specs.iter().map(|f| &f.name).collect();
    let consts: Vec<Ident> = specs
        .iter()
        .map(|f| format_ident!("{}", f.name.to_uppercase()))
        .collect();
    let vis = &input.vis;
    let params = specs.iter().zip(&consts).map(|(f, c)| {
        let (n, u, d) = (&f.name, &f.unit, &f.doc);
        let domain = domain_text(f);
        let what = format!(
            "The parameter `{n}` of `{name}`: its name, unit, default and domain, for errors that report it."
        );
        let def = match &f.default {
            None => quote!(::core::option::Option::None),
            Some(None) => quote!(::core::option::Option::Some(#core::spec::OPTIONAL)),
            Some(Some(e)) => {
                let s = default_text(e);
                quote!(::core::option::Option::Some(#s))
            }
        };
        quote! {
            #[doc = #what]
            #vis const #c: #core::Param = #core::Param {
                operator: #name, name: #n, unit: #u, doc: #d, default: #def, domain: #domain,
            };
        }
    });
    let checks = specs
        .iter()
        .zip(&consts)
        .filter(|(f, _)| f.checked)
        .map(|(f, c)| {
            let id = &f.ident;
            let conds = f.bounds.iter().map(|(k, b)| match *k {
                Bound::Gt => quote!(__v > (#b)),
                Bound::Ge => quote!(__v >= (#b)),
                Bound::Lt => quote!(__v < (#b)),
                Bound::Le => quote!(__v <= (#b)),
            });
            // A format string: braces in a bound's text are escaped.
            let esc = |t: String| t.replace('{', "{{").replace('}', "}}");
            let mut fmt = format!("must be {}", esc(domain_text(f)));
            let mut args = Vec::new();
            for (_, b) in &f.bounds {
                if !is_literal(b) && bound_text(b) != "π" {
                    fmt.push_str(&format!(" ({} = {{}})", esc(bound_text(b))));
                    args.push(b.clone());
                }
            }
            // Spanned at the field's type: a domain on a type without one is reported there.
            let fty = &f.ty;
            let call = quote_spanned!(fty.span()=> <#fty as #core::ParamValue>::check_param);
            quote! {
                #call(
                    &self.#id,
                    &#ty::#c,
                    |__v: f64| true #(&& #conds)*,
                    || ::std::format!(#fmt #(, #args)*),
                )?;
            }
        });
    let slots: Vec<Ident> = specs.iter().map(|f| format_ident!("__{}", f.ident)).collect();
    let decls = specs.iter().zip(&slots).map(|(f, s)| {
        let t = &f.ty;
        quote!(let mut #s: ::core::option::Option<#t> = ::core::option::Option::None;)
    });
    let arms = specs.iter().zip(&slots).map(|(f, s)| {
        let n = &f.name;
        let read = if f.nested {
            quote!(#serde::de::MapAccess::next_value_seed(&mut __map, #core::spec::NestedSeed(self.0))?)
        } else {
            quote!(#serde::de::MapAccess::next_value(&mut __map)?)
        };
        quote!(#n => {
            if #s.is_some() {
                return ::core::result::Result::Err(<__A::Error as #serde::de::Error>::duplicate_field(#n));
            }
            #s = ::core::option::Option::Some(#read);
        })
    });
    let default_value = |f: &FieldSpec| match &f.default {
        Some(Some(e)) => Some(default_expr(&f.ty, e)),
        Some(None) => Some(quote!(::core::default::Default::default())),
        None => None,
    };
    let finish = specs.iter().zip(&slots).map(|(f, s)| {
        let id = &f.ident;
        let n = &f.name;
        match default_value(f) {
            Some(d) => quote!(#id: match #s { ::core::option::Option::Some(v) => v, ::core::option::Option::None => #d },),
            None => quote!(#id: #s.ok_or_else(|| <__A::Error as #serde::de::Error>::missing_field(#n))?,),
        }
    });
    let defaults = if specs.iter().all(|f| f.default.is_some()) {
        let inits = specs.iter().map(|f| {
            let id = &f.ident;
            let d = default_value(f);
            quote!(#id: #d,)
        });
        quote!(::core::option::Option::Some(#ty { #(#inits)* }))
    } else {
        quote!(::core::option::Option::None)
    };
    let expecting = format!("the parameters of `{name}`");
    Ok(quote! {
        impl #ty {
            #(#params)*
        }

        impl #core::OperatorSpec for #ty {
            const NAME: &'static str = #name;
            const SUMMARY: &'static str = #summary;
            const PARAMS: &'static [#core::Param] = &[#(#ty::#consts),*];

            #[inline(always)]
            // `lo < v && v <= hi` is written as declared; the message says the same.
            #[allow(clippy::manual_range_contains)]
            fn check(&self) -> ::core::result::Result<(), #core::CovError> {
                #(#checks)*
                ::core::result::Result::Ok(())
            }

            fn deserialize_in<'de, __D: #serde::Deserializer<'de>, __R: #core::OperatorReader>(
                d: __D,
                reader: &__R,
            ) -> ::core::result::Result<Self, __D::Error> {
                const FIELDS: &[&str] = &[#(#names),*];
                struct __Visitor<'r, R>(&'r R);
                impl<'de, 'r, R: #core::OperatorReader> #serde::de::Visitor<'de> for __Visitor<'r, R> {
                    type Value = #ty;
                    fn expecting(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                        f.write_str(#expecting)
                    }
                    fn visit_map<__A: #serde::de::MapAccess<'de>>(self, mut __map: __A) -> ::core::result::Result<#ty, __A::Error> {
                        #(#decls)*
                        while let ::core::option::Option::Some(__key) =
                            #serde::de::MapAccess::next_key_seed(&mut __map, #core::spec::FieldName)?
                        {
                            match __key.as_str() {
                                #(#arms)*
                                __other => {
                                    return ::core::result::Result::Err(
                                        <__A::Error as #serde::de::Error>::unknown_field(__other, FIELDS),
                                    );
                                }
                            }
                        }
                        ::core::result::Result::Ok(#ty { #(#finish)* })
                    }
                }
                #serde::Deserializer::deserialize_struct(d, #name, FIELDS, __Visitor(reader))
            }

            fn defaults() -> ::core::option::Option<Self> {
                #defaults
            }
        }
    })
}

/// A default as a path file would write it: an enum variant by its own name (`Y` for
/// `Which::Y`), a negative number without the space `quote` puts after its sign (`-1.5`),
/// any other expression as its tokens.
fn default_text(e: &Expr) -> String {
    match e {
        Expr::Path(p) => p
            .path
            .segments
            .last()
            .map_or_else(|| quote!(#e).to_string(), |s| s.ident.to_string()),
        Expr::Unary(syn::ExprUnary {
            op: syn::UnOp::Neg(_),
            expr,
            ..
        }) => format!("-{}", default_text(expr)),
        _ => quote!(#e).to_string(),
    }
}
