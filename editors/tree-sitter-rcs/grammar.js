/**
 * @file Tree-sitter grammar for the RCS plan language (`.rcs`).
 *
 * An editor grammar for highlighting and structure (Neovim, Helix, Zed).
 * The source of truth for the syntax is rcs-dsl's pest grammar
 * (`rcs-dsl/src/grammar.pest`) and LANGUAGE.md; this grammar accepts every
 * file that grammar accepts and may accept a little more (checks that the
 * compiler makes while building its tree, such as reserved words, unknown
 * duration units or a bitwise operator mixed with a comparison, are left
 * to `rcsc check` and the language server).
 *
 * Expression precedence, loosest first (rcs-dsl `BinOp::precedence`):
 * `||`, `&&`, comparisons, `|`, `^`, `&`, `<<` `>>`, `+` `-`, `*` `/` `%`,
 * unary `!` `-`, `as` casts, then field access, indexing and calls (which,
 * as in pest's compound-atomic `postfix_expr`, take no space before `.`,
 * `[`, `(` or `::`).
 */

/* eslint-disable arrow-parens, camelcase */

const PREC = {
  or: 1,
  and: 2,
  compare: 3,
  bit_or: 4,
  bit_xor: 5,
  bit_and: 6,
  shift: 7,
  additive: 8,
  multiplicative: 9,
  unary: 10,
  cast: 11,
  postfix: 12,
};

/** `rule ("," rule)* ","?` — a comma-separated list with a trailing comma. */
function commaSep1(rule) {
  return seq(rule, repeat(seq(',', rule)), optional(','));
}

/** An optional `commaSep1`. */
function commaSep(rule) {
  return optional(commaSep1(rule));
}

module.exports = grammar({
  name: 'rcs',

  word: $ => $.identifier,

  extras: $ => [
    // pest's WHITESPACE: space and \t..\r; a byte-order mark may open a file.
    /[ \t\n\x0B\f\r\uFEFF]/,
    $.comment,
  ],

  supertypes: $ => [
    $._item,
    $._entry,
    $._expression,
    $._job,
  ],

  rules: {
    source_file: $ => repeat($._item_with_outer),

    // ------------------------------------------------------------ lexical

    identifier: _ => /[A-Za-z_][A-Za-z0-9_]*/,

    // Integers (decimal with `_`, `0x…`, `0b…`), floats with exponents, and
    // an optional unit (`50ms`, `1.5s`: durations, LANGUAGE.md §8).
    number: _ => token(seq(
      choice(
        /0x[0-9A-Fa-f_]+/,
        /0b[01_]+/,
        /[0-9][0-9_]*(\.[0-9][0-9_]*([eE][+-]?[0-9][0-9_]*)?|[eE][+-]?[0-9][0-9_]*)?/,
      ),
      optional(/[A-Za-z_][A-Za-z0-9_]*/),
    )),

    string: _ => token(seq('"', repeat(choice(/[^"\\\n\r]/, /\\[\s\S]/)), '"')),

    // `//` and `/* */`. `////…` is a comment; exactly `///` is a doc comment.
    comment: _ => token(choice(
      seq('//', /[^\n\r]*/),
      seq('/*', /[^*]*\*+([^/*][^*]*\*+)*/, '/'),
    )),

    doc_comment: _ => token(prec(1, /\/\/\/([^\/\n\r][^\n\r]*)?/)),

    // ------------------------------------------------------------ items

    _item_with_outer: $ => seq(repeat($._outer), $._item),

    _outer: $ => choice($.doc_comment, $.attribute),

    // `#[allow(LINT, …)]`, `#[warn(…)]`, `#[deny(…)]`
    attribute: $ => seq(
      '#', '[',
      field('level', alias(choice('allow', 'warn', 'deny'), $.lint_level)),
      '(', commaSep1(field('lint', $.identifier)), ')',
      ']',
    ),

    _item: $ => choice(
      $.enum_definition,
      $.buffer_definition,
      $.controller_type_definition,
      $.controller_instance,
      $.controller_definition,
      $.const_definition,
    ),

    const_definition: $ => seq(
      'const',
      field('name', $.identifier),
      ':',
      field('type', $._type),
      '=',
      field('value', $._expression),
    ),

    enum_definition: $ => seq(
      'enum',
      field('name', $.identifier),
      field('body', $.variant_list),
    ),

    variant_list: $ => seq('{', commaSep($.variant), '}'),

    variant: $ => seq(repeat($.doc_comment), field('name', $.identifier)),

    buffer_definition: $ => seq(
      'buffer',
      field('name', $.identifier),
      field('body', $.field_list),
    ),

    field_list: $ => seq('{', commaSep($.field_declaration), '}'),

    field_declaration: $ => seq(
      repeat($.doc_comment),
      field('name', $.identifier),
      ':',
      field('type', $._type),
    ),

    _type: $ => choice($.array_type, $._type_identifier),

    _type_identifier: $ => alias($.identifier, $.type_identifier),

    array_type: $ => seq(
      '[',
      field('element', $._type),
      ';',
      field('length', $._expression),
      ']',
    ),

    controller_definition: $ => seq(
      'controller',
      field('name', $.identifier),
      optional(field('title', $.string)),
      field('body', $.controller_body),
    ),

    // `controller type T(c: TYPE, …) "title" { … }` (§8)
    controller_type_definition: $ => seq(
      'controller',
      'type',
      field('name', $.identifier),
      optional(field('parameters', $.parameter_list)),
      optional(field('title', $.string)),
      field('body', $.controller_body),
    ),

    // `controller NAME = T(c: value, …) "title" { local: global, … }` (§8)
    controller_instance: $ => seq(
      'controller',
      field('name', $.identifier),
      '=',
      field('type', $.identifier),
      optional(field('arguments', $.named_argument_list)),
      optional(field('title', $.string)),
      optional(field('bindings', $.binding_list)),
    ),

    binding_list: $ => seq('{', repeat(seq($.binding, optional(','))), '}'),

    binding: $ => seq(
      field('local', $.identifier),
      ':',
      field('global', $.identifier),
    ),

    controller_body: $ => seq('{', repeat($._entry_with_outer), '}'),

    // ------------------------------------------------------------ entries

    _entry_with_outer: $ => seq(repeat($._outer), $._entry),

    _entry: $ => choice(
      $.level_declaration,
      $.subordinates_declaration,
      $.reads_declaration,
      $.writes_declaration,
      $.command_declaration,
      $.status_field_declaration,
      $.status_declaration,
      $.error_declaration,
      $.var_declaration,
      $.hook_declaration,
      $.plan_definition,
      $.const_definition,
      $.every_cycle_block,
      $.rows_definition,
      $.jobs_definition,
    ),

    level_declaration: $ => seq('level', field('level', $.number)),

    subordinates_declaration: $ => seq(
      'subordinates',
      $.identifier,
      repeat(seq(',', $.identifier)),
    ),

    reads_declaration: $ => seq(
      'reads',
      field('name', $.identifier),
      ':',
      field('type', $._type_identifier),
    ),

    writes_declaration: $ => seq(
      'writes',
      field('name', $.identifier),
      ':',
      field('type', $._type_identifier),
    ),

    command_declaration: $ => prec.right(seq(
      'command',
      field('name', $.identifier),
      optional(field('parameters', $.parameter_list)),
      optional(field('accept', $.accept_clause)),
    )),

    // `accept when COND` (§8)
    accept_clause: $ => seq('accept', 'when', field('condition', $._expression)),

    parameter_list: $ => seq('(', commaSep($.parameter), ')'),

    parameter: $ => seq(
      repeat($.doc_comment),
      field('name', $.identifier),
      ':',
      field('type', $._type),
    ),

    // `status AT_GOAL, HOLDING`: status values.
    status_declaration: $ => seq(
      'status',
      $.identifier,
      repeat(seq(',', $.identifier)),
    ),

    // `status NAME: TYPE = INIT`: a status field (§7).
    status_field_declaration: $ => seq(
      'status',
      field('name', $.identifier),
      ':',
      field('type', $._type),
      optional(seq('=', field('value', $._expression))),
    ),

    error_declaration: $ => seq(
      'error',
      $.identifier,
      repeat(seq(',', $.identifier)),
    ),

    var_declaration: $ => seq(
      'var',
      field('name', $.identifier),
      ':',
      field('type', $._type),
      optional(seq('=', field('value', $._expression))),
    ),

    hook_declaration: $ => prec.right(seq(
      'hook',
      field('name', $.identifier),
      field('parameters', $.parameter_list),
      optional(seq('->', field('return_type', $._type))),
    )),

    // `pre { jobs }`, `post { jobs }` (§7). A target after the block is
    // parsed, as pest does, so that the compiler can refuse it in words.
    every_cycle_block: $ => prec.right(seq(
      field('kind', choice('pre', 'post')),
      field('jobs', $.job_list),
      optional(seq('->', field('target', $.target))),
    )),

    // `jobs NAME(p: T, …) { job… }`: a named job list (§8).
    jobs_definition: $ => seq(
      'jobs',
      field('name', $.identifier),
      field('parameters', $.parameter_list),
      field('body', $.job_list),
    ),

    // `rows NAME { row… }`: shared rows (§8).
    rows_definition: $ => seq(
      'rows',
      field('name', $.identifier),
      field('body', $.plan_body),
    ),

    // ------------------------------------------------------------ plans

    // `plan A | B | C { … }`: one plan for several verbs.
    plan_definition: $ => seq(
      'plan',
      field('verb', $.identifier),
      repeat(seq('|', field('verb', $.identifier))),
      field('body', $.plan_body),
    ),

    plan_body: $ => seq('{', repeat(choice($.use_rows, $.row)), '}'),

    // `use NAME`: the rows of block NAME, here.
    use_rows: $ => seq('use', field('name', $.identifier)),

    // [label ":"] [from] ("when" COND | "otherwise") "->" target [jobs]
    row: $ => prec.right(seq(
      repeat($.doc_comment),
      // `E3:` (pest checks the `E` + digits shape; here any name before `:`).
      optional(seq(field('label', alias($.identifier, $.row_label)), ':')),
      optional(field('from', $._from)),
      choice(
        seq('when', field('condition', $._expression)),
        field('otherwise', $.otherwise),
      ),
      '->',
      field('target', $.target),
      optional(field('jobs', $.job_list)),
    )),

    otherwise: _ => 'otherwise',

    _from: $ => choice($.dont_care, $.state_set),

    // `*`, `*N`, `*N except A | B` (§8)
    dont_care: $ => seq(
      field('marker', $.dont_care_marker),
      optional(seq('except', field('except', $.state_set))),
    ),

    dont_care_marker: _ => /\*[0-9]*/,

    // `A` or `A | B | C` (§8). A state may be named like the contextual
    // keyword `use` (`use when …`), as in pest.
    state_set: $ => seq($.state, repeat(seq('|', $.state))),

    state: $ => choice($.identifier, alias('use', $.identifier)),

    // `same`, `Error`, `Error(CODE)` or a state.
    target: $ => choice(
      alias('same', $.same),
      $.error_target,
      $.state,
    ),

    error_target: $ => prec.right(seq(
      'Error',
      optional(seq('(', field('code', $.identifier), ')')),
    )),

    // ------------------------------------------------------------ jobs

    job_list: $ => seq('{', repeat(seq($._job, repeat(';'))), '}'),

    _job: $ => choice(
      $.report_job,
      $.assignment_job,
      $.send_job,
      $.call_job,
    ),

    // `report S`, `report DONE`, `report ERROR(CODE)`
    report_job: $ => prec.right(seq(
      'report',
      field('status', $.identifier),
      optional(seq('(', field('code', $.identifier), ')')),
    )),

    // `x = e`, `x += e`, `x -= e`
    assignment_job: $ => seq(
      field('left', $._postfix_expression),
      field('operator', choice('=', '+=', '-=')),
      field('right', $._expression),
    ),

    // `X <- VERB`, `X <- VERB(p: e, …)`, `X <- cmd`
    send_job: $ => prec.right(seq(
      field('subordinate', $._postfix_expression),
      '<-',
      field('verb', $.identifier),
      optional(field('arguments', $.named_argument_list)),
    )),

    // A hook or job-list call (or any operand, which the compiler refuses
    // as a job that does nothing).
    call_job: $ => prec(-1, $._postfix_expression),

    named_argument_list: $ => seq('(', commaSep($.named_argument), ')'),

    named_argument: $ => seq(
      field('name', $.identifier),
      ':',
      field('value', $._expression),
    ),

    // ------------------------------------------------------------ expressions

    _expression: $ => choice(
      $.binary_expression,
      $.unary_expression,
      $.cast_expression,
      $._postfix_expression,
    ),

    _postfix_expression: $ => choice(
      $.identifier,
      $.number,
      $.parenthesized_expression,
      $.call_expression,
      $.path_expression,
      $.field_expression,
      $.index_expression,
    ),

    binary_expression: $ => {
      const table = [
        [PREC.or, '||'],
        [PREC.and, '&&'],
        [PREC.compare, choice('==', '!=', '<', '<=', '>', '>=')],
        [PREC.bit_or, '|'],
        [PREC.bit_xor, '^'],
        [PREC.bit_and, '&'],
        [PREC.shift, choice('<<', '>>')],
        [PREC.additive, choice('+', '-')],
        [PREC.multiplicative, choice('*', '/', '%')],
      ];
      return choice(...table.map(([precedence, operator]) => prec.left(precedence, seq(
        field('left', $._expression),
        field('operator', operator),
        field('right', $._expression),
      ))));
    },

    unary_expression: $ => prec(PREC.unary, seq(
      field('operator', choice('!', '-')),
      field('operand', $._expression),
    )),

    // `x as u8`: binds tighter than a unary operator (`-x as u8` is `-(x as u8)`).
    cast_expression: $ => prec.left(PREC.cast, seq(
      field('value', $._expression),
      'as',
      field('type', $._type_identifier),
    )),

    parenthesized_expression: $ => seq('(', $._expression, ')'),

    // `f(a, b)`: a hook, a job list or a built-in function.
    call_expression: $ => prec(PREC.postfix, seq(
      field('function', $.identifier),
      field('arguments', $.argument_list),
    )),

    argument_list: $ => seq(token.immediate('('), commaSep($._expression), ')'),

    // `Type::VARIANT`
    path_expression: $ => prec(PREC.postfix, seq(
      field('path', $.identifier),
      token.immediate('::'),
      field('name', $.identifier),
    )),

    // `ship.speed`, `TB.done`, `cmd.speed`
    field_expression: $ => prec(PREC.postfix, seq(
      field('value', $._postfix_expression),
      token.immediate('.'),
      field('field', alias($.identifier, $.field_identifier)),
    )),

    // `a[i]`
    index_expression: $ => prec(PREC.postfix, seq(
      field('value', $._postfix_expression),
      token.immediate('['),
      field('index', $._expression),
      ']',
    )),
  },
});
