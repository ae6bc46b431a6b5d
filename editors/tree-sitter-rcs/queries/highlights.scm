; Highlighting for the RCS plan language (.rcs).
;
; The patterns are written so that no two of them capture the same node
; (where a name is special, the general pattern excludes it with
; `#not-any-of?`): editors differ in whether the first or the last matching
; pattern wins (Helix and the tree-sitter CLI take the first, Neovim the
; last), and disjoint patterns read the same in all of them. Capture names
; are the common dotted ones; an editor without a theme entry for
; `@comment.documentation` falls back to `@comment`, and so on.
;
; Enum variants, statuses and error codes used in expressions cannot be told
; from variables without the plan set's declarations: the language server's
; semantic tokens (`rcsc lsp`) colour those.

; ------------------------------------------------------------ comments

(comment) @comment
(doc_comment) @comment.documentation

; ------------------------------------------------------------ literals

(number) @number
(string) @string

((identifier) @boolean
  (#any-of? @boolean "true" "false"))

; ------------------------------------------------------------ keywords

[
  "enum"
  "buffer"
  "controller"
  "type"
  "level"
  "subordinates"
  "reads"
  "writes"
  "command"
  "status"
  "error"
  "var"
  "hook"
  "plan"
  "const"
  "pre"
  "post"
  "rows"
  "jobs"
  "use"
  "except"
  "accept"
  "report"
] @keyword

[
  "when"
  (otherwise)
] @keyword.conditional

"as" @keyword.operator

(same) @keyword

(error_target "Error" @constant.builtin)

; ------------------------------------------------------------ attributes

(attribute "#" @punctuation.special)
(lint_level) @attribute
(attribute lint: (identifier) @constant)

; ------------------------------------------------------------ items and entries

(enum_definition name: (identifier) @type)
(variant name: (identifier) @constant)
(buffer_definition name: (identifier) @type)
(field_declaration name: (identifier) @property)

(controller_definition name: (identifier) @type)
(controller_type_definition name: (identifier) @type)
(controller_instance name: (identifier) @type)
(controller_instance type: (identifier) @type)
(binding local: (identifier) @property)
(binding global: (identifier) @variable)

((type_identifier) @type.builtin
  (#any-of? @type.builtin
    "bool" "i8" "i16" "i32" "i64" "u8" "u16" "u32" "u64" "f32" "f64" "duration" "error"))
((type_identifier) @type
  (#not-any-of? @type
    "bool" "i8" "i16" "i32" "i64" "u8" "u16" "u32" "u64" "f32" "f64" "duration" "error"))

(const_definition name: (identifier) @constant)
(subordinates_declaration (identifier) @type)
(reads_declaration name: (identifier) @variable)
(writes_declaration name: (identifier) @variable)
(command_declaration name: (identifier) @function)
(status_declaration (identifier) @constant)
(status_field_declaration name: (identifier) @property)
(error_declaration (identifier) @constant)
(var_declaration name: (identifier) @variable)
(hook_declaration name: (identifier) @function)
(jobs_definition name: (identifier) @function)
(rows_definition name: (identifier) @function)
(parameter name: (identifier) @variable.parameter)

; ------------------------------------------------------------ plans and rows

(plan_definition verb: (identifier) @function)
(use_rows name: (identifier) @function)
(row_label) @label
(dont_care_marker) @label

((state (identifier) @constant.builtin)
  (#any-of? @constant.builtin "S0" "Done"))
((state (identifier) @constant)
  (#not-any-of? @constant "S0" "Done"))

(error_target code: (identifier) @constant)

; ------------------------------------------------------------ jobs

(report_job status: (identifier) @constant)
(report_job code: (identifier) @constant)
; `X <- cmd` forwards the current command: `cmd` is the built-in below.
(send_job
  verb: (identifier) @function
  (#not-eq? @function "cmd"))
(named_argument name: (identifier) @variable.parameter)

; ------------------------------------------------------------ expressions

; Reserved names with a meaning of their own (LANGUAGE.md §3, §8).
((identifier) @variable.builtin
  (#any-of? @variable.builtin
    "cmd" "new_command" "state_cycles" "plan_cycles" "state_time" "plan_time"))

; Built-in functions (LANGUAGE.md §7: names reserved).
(call_expression
  function: (identifier) @function.builtin
  (#any-of? @function.builtin
    "abs" "min" "max" "clamp" "sqrt" "sin" "cos" "tan" "asin" "acos" "atan" "atan2"
    "exp" "ln" "floor" "ceil" "round" "hypot" "is_nan"))
(call_expression
  function: (identifier) @function.call
  (#not-any-of? @function.call
    "abs" "min" "max" "clamp" "sqrt" "sin" "cos" "tan" "asin" "acos" "atan" "atan2"
    "exp" "ln" "floor" "ceil" "round" "hypot" "is_nan"))

(path_expression path: (identifier) @type)
(path_expression name: (identifier) @constant)
(field_identifier) @property

; ------------------------------------------------------------ operators and punctuation

[
  "||" "&&" "==" "!=" "<" "<=" ">" ">="
  "|" "^" "&" "<<" ">>"
  "+" "-" "*" "/" "%" "!"
  "=" "+=" "-="
  "<-" "->"
] @operator

["(" ")" "[" "]" "{" "}"] @punctuation.bracket
["," ";" ":" "." "::"] @punctuation.delimiter
